"""A synthetic impact-outcome dataset: golf-ball oblique impacts on a rigid plate, one per row.

Rows: inbound speeds 20, 30 and 40 m/s at incidences 10 to 70 deg from the surface normal.
Ball (45.9 g, 21.35 mm, I = 0.4 m r^2) with a half-sine normal force whose contact time and
restitution fall with the normal speed (t_c = 450 us (v_n / 30 m/s)^(-1/5), e = 0.78 - 0.004 s/m
(v_n - 30 m/s)), slip coupling and stick, Coulomb friction mu = 0.25. Below tan(theta) =
(7/2) mu (1 + e) the ball grips (rolls before rebound), above it slides throughout: the
outcomes show the grip-slip transition of the rigid-sphere theory. Outcomes come from
``frictionlab.solve.outcome.predict_outcomes`` (exact solver) plus Gaussian noise from numpy's
default_rng(SEED), rounded to 6 significant digits.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ...solve.outcome import OutcomeScene, SpeedLaw, predict_outcomes
from .write import write_pair

NAME = "impact-outcome-synthetic"
SEED = 3000
SPEEDS = (20.0, 30.0, 40.0)  # [m/s]
INCIDENCES_DEG = (10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0)
BALL = dict(mass=0.0459, radius=0.02135, inertia_factor=0.4)
PULSE = dict(contact_time=450e-6, restitution=0.78, reference_speed=30.0, exponent=-0.2, slope=0.004)
TRUTH = dict(law="coulomb", mu=0.25)
RPM = 2.0 * math.pi / 60.0
NOISE = {"rebound_spin": 100 * RPM, "tangential_cor": 0.02, "rebound_angle": math.radians(0.5)}


def scene() -> OutcomeScene:
    """The generating scene (the TOML's [scene] says the same in units)."""
    return OutcomeScene(
        mass=BALL["mass"], radius=BALL["radius"], inertia_factor=BALL["inertia_factor"],
        normal={"model": "half-sine", "modulus": None,
                "contact_time": SpeedLaw(PULSE["contact_time"], PULSE["reference_speed"], PULSE["exponent"]),
                "restitution": SpeedLaw(PULSE["restitution"], PULSE["reference_speed"], 0.0, -PULSE["slope"])})


def build(out_dir: Path) -> list[Path]:
    speed = np.repeat(SPEEDS, len(INCIDENCES_DEG))
    incidence = np.tile(INCIDENCES_DEG, len(SPEEDS))
    out = predict_outcomes(TRUTH["law"], scene(), {"mu": TRUTH["mu"]}, "exact", speed=speed,
                           incidence=np.radians(incidence))
    rng = np.random.default_rng(SEED)
    noisy = {k: out[k] + rng.normal(0.0, NOISE[k], out[k].shape) for k in NOISE}
    columns = {"speed": speed, "incidence": incidence, "rebound_spin": noisy["rebound_spin"] / RPM,
               "tangential_cor": noisy["tangential_cor"], "rebound_angle": np.degrees(noisy["rebound_angle"])}
    noise_text = {"rebound_spin": "100 rpm", "tangential_cor": "0.02", "rebound_angle": "0.5 deg"}
    meta = {
        "name": NAME,
        "kind": "impact-outcome",
        "observable": "rebound_spin",
        "description": ("Golf-ball-like oblique impacts on a rigid plate, one impact per row: inbound speed and "
                        "incidence (from the surface normal) in, rebound spin, tangential restitution of the "
                        "contact point and rebound angle out. SYNTHETIC: generated with Coulomb friction "
                        "(rigid sphere, slip coupling and stick), not measured."),
        "columns": {"speed": "m/s", "incidence": "deg", "rebound_spin": "rpm", "tangential_cor": "",
                    "rebound_angle": "deg"},
        "noise": {"kind": "known", **noise_text},
        "scene": {
            "mass": f"{BALL['mass'] * 1e3:g} g", "radius": f"{BALL['radius'] * 1e3:g} mm",
            "inertia_factor": BALL["inertia_factor"], "effects": ["spin", "slip-coupling"],
            "angle_reference": "normal",
            "normal": {"model": "half-sine", "contact_time": f"{PULSE['contact_time'] * 1e6:g} us",
                       "restitution": PULSE["restitution"], "reference_speed": f"{PULSE['reference_speed']:g} m/s",
                       "contact_time_exponent": PULSE["exponent"],
                       "restitution_slope": f"{PULSE['slope']:g} s/m"},
            # for laws that read A or dA/dt (the generating Coulomb law does not): a half-sine area whose
            # peak grows as v_n^(4/5) (Hertz), 150 mm^2 at the reference speed, as the paper's golf ball
            "area": {"model": "half-sine", "peak": "150 mm^2", "reference_speed": f"{PULSE['reference_speed']:g} m/s"},
        },
        "provenance": {
            "kind": "synthetic",
            "source": ("synthetic; golf-ball oblique impact of the kind measured by Arakawa (Sci. Rep. 2017) and "
                       "others, rigid-sphere Coulomb theory (no numbers taken from a measurement)"),
            "method": ("frictionlab.solve.outcome.predict_outcomes('coulomb', exact solver) for every row of this scene, "
                       "plus Gaussian noise of the stated sigma from numpy default_rng(seed); 6 significant "
                       "digits. See frictionlab/io/datagen/outcome.py."),
            "command": "frictionlab datasets rebuild",
            "seed": SEED,
            "truth": {"law": TRUTH["law"], "mu": TRUTH["mu"], "solver": "exact", "noise": noise_text},
        },
    }
    return write_pair(out_dir, NAME, meta, columns, 6, __name__)
