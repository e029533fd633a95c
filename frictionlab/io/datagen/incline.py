"""Synthetic incline-sliding datasets, generated with a known law, parameters and seed.

Only the abstracts of Arakawa's incline papers are public, so no numbers of theirs exist to
reconstruct: these series are synthetic and say so. Parameters are plausible for the setups
the abstracts describe and are recorded in each TOML's [provenance.truth].

- Lubricated (PU rubber block on a PMMA incline under silicone oil): Couette friction,
  F = (eta/h) A u, constant contact area, started from rest; three contact areas. The
  viscosity of the oil (0.1 Pa s, silicone oil of about 100 cSt) is known to the experimenter
  and is given in [fixed], so the film thickness h is identifiable.
- Dry (PTFE sphere on a glass incline): the wear law F = lam A u with the contact area
  growing with sliding length, A = A0 + k x, started from rest: the velocity rises to a
  maximum and then falls as the area grows. Two sphere sizes (initial areas).

Series come from ``frictionlab.simulate`` (exact for lubricated, ode at rtol 1e-12 for dry)
plus Gaussian noise from numpy's default_rng(seed), rounded to 6 significant digits.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ...physics.scene import ConstantArea, GrowthArea, Scene
from ...solve.solvers import simulate
from .write import write_pair

SOURCE_OIL = ("synthetic; setup after Arakawa, Tribol. Int. (2016), PU rubber on an oiled PMMA incline "
              "(abstract only: no numbers taken from it)")
SOURCE_DRY = ("synthetic; setup after Arakawa, 'Effects of wear on contact area and dynamic sliding velocity' "
              "(PTFE on glass; abstract only: no numbers taken from it)")

OIL = dict(mass=0.020, incline_deg=20.0, eta=0.1, h=40e-6, noise=0.003, dt=0.005, t_end=0.5)
OIL_AREAS_MM2 = (100, 200, 400)
DRY = dict(incline_deg=30.0, lam=2.0e4, rate_mm2_per_m=1.0, noise=0.01, dt=0.02, t_end=2.0)
DRY_SPHERES = ((10.0, 0.10), (12.7, 0.20))  # (diameter mm, initial area mm^2)
PTFE_DENSITY = 2200.0  # kg/m^3


def build(out_dir: Path) -> list[Path]:
    written = []
    for i, a_mm2 in enumerate(OIL_AREAS_MM2):
        written += _oil(out_dir, a_mm2, seed=1000 + i)
    for i, (d_mm, a0_mm2) in enumerate(DRY_SPHERES):
        written += _dry(out_dir, d_mm, a0_mm2, seed=2000 + i)
    return written


def _noisy(v, sigma, seed):
    return v + np.random.default_rng(seed).normal(0.0, sigma, v.shape)


def _oil(out_dir, a_mm2, seed):
    c = OIL
    alpha = math.radians(c["incline_deg"])
    t = np.round(np.arange(0.0, c["t_end"] + c["dt"] / 2, c["dt"]), 10)
    scene = Scene(kind="incline", mass=c["mass"], u0=0.0, duration=c["t_end"], incline=alpha,
                  area=ConstantArea(a_mm2 * 1e-6), effects=frozenset({"gravity"}))
    traj = simulate("couette", scene, {"eta": c["eta"], "h": c["h"]}, solver="exact", t=t)
    v = _noisy(traj.v, c["noise"], seed)
    name = f"incline-oil-a{a_mm2}"
    meta = {
        "name": name,
        "group": "incline-oil",  # one rubber, oil and incline at three contact areas
        "kind": "incline",
        "observable": "v",
        "description": (f"PU-rubber-like block ({c['mass'] * 1e3:g} g, contact area {a_mm2} mm^2) sliding from rest "
                        f"down a {c['incline_deg']:g} deg PMMA incline under silicone oil. SYNTHETIC: generated with "
                        "the Couette law, not measured."),
        "columns": {"t": "s", "v": "m/s"},
        "noise": {"kind": "known", "v": f"{c['noise'] * 1e3:g} mm/s"},
        "scene": {"mass": f"{c['mass'] * 1e3:g} g", "u0": "0 m/s", "incline": f"{c['incline_deg']:g} deg",
                  "area": {"model": "constant", "area": f"{a_mm2} mm^2"}},
        "fixed": {"eta": f"{c['eta']:g} Pa s"},
        "provenance": {
            "kind": "synthetic",
            "source": SOURCE_OIL,
            "method": ("frictionlab.simulate('couette', exact) on this scene, plus Gaussian noise of the stated "
                       "sigma from numpy default_rng(seed); 6 significant digits. See frictionlab/io/datagen/incline.py."),
            "command": "frictionlab datasets rebuild",
            "seed": seed,
            "truth": {"law": "couette", "eta": f"{c['eta']:g} Pa s", "h": f"{c['h'] * 1e6:g} um",
                      "noise": f"{c['noise'] * 1e3:g} mm/s"},
        },
    }
    return write_pair(out_dir, name, meta, {"t": t, "v": v}, 6, __name__)


def _dry(out_dir, d_mm, a0_mm2, seed):
    c = DRY
    alpha = math.radians(c["incline_deg"])
    mass = PTFE_DENSITY * math.pi / 6.0 * (d_mm * 1e-3) ** 3
    t = np.round(np.arange(0.0, c["t_end"] + c["dt"] / 2, c["dt"]), 10)
    rate = c["rate_mm2_per_m"] * 1e-6
    scene = Scene(kind="incline", mass=mass, u0=0.0, duration=c["t_end"], incline=alpha,
                  area=GrowthArea(a0_mm2 * 1e-6, rate), effects=frozenset({"gravity"}))
    traj = simulate("wear", scene, {"lam": c["lam"]}, solver="ode:DOP853", t=t, rtol=1e-12)
    v = _noisy(traj.v, c["noise"], seed)
    name = f"incline-dry-d{d_mm:g}".replace(".", "p")
    meta = {
        "name": name,
        "group": "incline-dry",  # one PTFE-on-glass setup at two contact sizes
        "kind": "incline",
        "observable": "v",
        "description": (f"PTFE sphere ({d_mm:g} mm, {mass * 1e3:.3g} g) sliding from rest down a {c['incline_deg']:g} deg "
                        f"glass incline, contact area growing with wear from {a0_mm2:g} mm^2 by "
                        f"{c['rate_mm2_per_m']:g} mm^2 per metre slid. SYNTHETIC: generated with the wear law, "
                        "not measured."),
        "columns": {"t": "s", "v": "m/s"},
        "noise": {"kind": "known", "v": f"{c['noise'] * 1e3:g} mm/s"},
        "scene": {"mass": f"{mass * 1e3:.6g} g", "radius": f"{d_mm / 2:g} mm", "u0": "0 m/s",
                  "incline": f"{c['incline_deg']:g} deg",
                  "area": {"model": "growth", "initial": f"{a0_mm2:g} mm^2", "rate": f"{c['rate_mm2_per_m']:g} mm^2/m"}},
        "provenance": {
            "kind": "synthetic",
            "source": SOURCE_DRY,
            "method": ("frictionlab.simulate('wear', ode:DOP853, rtol 1e-12) on this scene, plus Gaussian noise of "
                       "the stated sigma from numpy default_rng(seed); 6 significant digits. "
                       "See frictionlab/io/datagen/incline.py."),
            "command": "frictionlab datasets rebuild",
            "seed": seed,
            "truth": {"law": "wear", "lam": f"{c['lam']:g} Pa s/m", "noise": f"{c['noise'] * 1e3:g} mm/s"},
        },
    }
    return write_pair(out_dir, name, meta, {"t": t, "v": v}, 6, __name__)
