"""A synthetic slide-hold-slide record: ``frictionlab datasets rebuild --slide-hold-slide``.

A spring-slider (stiffness k per unit normal force) slides at 1 um/s to steady state, then holds for 1, 3, 10,
30, 100 and 300 s, re-sliding at 1 um/s for 100 s after each hold: the laboratory's healing test (Dieterich
1972; Beeler, Tullis and Weeks 1994; Marone 1998). The friction coefficient comes from
``frictionlab.simulate`` of the rate-state-aging law on the quasi-static spring-slider at rtol 1e-11, plus
Gaussian noise of 1e-4 from numpy's default_rng(seed), rounded to 7 significant digits, sampled at 10 Hz. The
truth (law, mu0, a, b, Dc; V0 = 1 um/s) is in the TOML's [provenance.truth]; the healing table it must give is
``frictionlab healing examples/slide-hold-slide/kt-slide-hold-slide.toml``.

k = 1e4 /m (0.01 1/um) is 25 times the critical stiffness (b - a)/Dc = 400 /m: the slider is stable.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ...physics.scene import ConstantNormal, Scene, SpringLoad
from ...solve.solvers import simulate
from .write import write_pair

NAME, LAW, SEED = "kt-slide-hold-slide", "rate-state-aging", 4100
TRUTH = dict(mu0=0.6, a=0.008, b=0.012, Dc=1e-5)
V, SLIDE, RESLIDE, HOLDS = 1e-6, 100.0, 100.0, (1.0, 3.0, 10.0, 30.0, 100.0, 300.0)
K, NORMAL, DT, NOISE = 1e4, 1e4, 0.1, 1e-4
COMMAND = "frictionlab datasets rebuild --slide-hold-slide"


def schedule() -> tuple[tuple, tuple, float]:
    """(segment start times [s], load-point velocities [m/s], end [s]) of the slide-hold-slide history."""
    times, vs, t = [0.0], [V], SLIDE
    for h in HOLDS:
        times += [t, t + h]
        vs += [0.0, V]
        t += h + RESLIDE
    return tuple(times), tuple(vs), t


def build(out_dir: Path) -> list[Path]:
    times, vs, end = schedule()
    scene = Scene(kind="spring-slider", mass=1.0, u0=V, duration=end, normal=ConstantNormal(NORMAL),
                  spring=SpringLoad(K, times, vs))
    t = np.round(np.arange(0.0, end + DT / 2, DT), 10)
    mu = simulate(LAW, scene, TRUTH, solver="ode:LSODA", t=t, rtol=1e-11).load
    mu = mu + np.random.default_rng(SEED).normal(0.0, NOISE, t.shape)
    meta = {
        "name": NAME,
        "kind": "spring-slider",
        "observable": "mu",
        "description": (f"Slide-hold-slide test: sliding at 1 um/s, holds of {', '.join(f'{h:g}' for h in HOLDS)} s, "
                        f"each followed by {RESLIDE:g} s of re-sliding, k = {K:g} /m per unit normal force. "
                        f"SYNTHETIC: generated with the {LAW} law, not measured."),
        "columns": {"t": "s", "mu": ""},
        "group": NAME,
        "noise": {"kind": "known", "mu": NOISE},
        "scene": {"mass": "1 kg", "normal": {"model": "constant", "value": f"{NORMAL:g} N"},
                  "spring": {"stiffness": f"{K:g} 1/m", "times": [f"{x:g} s" for x in times],
                             "velocities": [f"{v * 1e6:g} um/s" for v in vs]}},
        "provenance": {
            "kind": "synthetic",
            "source": "synthetic; the slide-hold-slide healing test of rate-and-state friction (Dieterich 1972; "
                      "Beeler, Tullis and Weeks 1994)",
            "method": (f"frictionlab.simulate('{LAW}', ode:LSODA, rtol 1e-11) on the quasi-static spring-slider, "
                       "plus Gaussian noise of the stated sigma from numpy default_rng(seed); 7 significant digits. "
                       "See frictionlab/io/datagen/holds.py."),
            "command": COMMAND,
            "seed": SEED,
            "truth": {"law": LAW, "mu0": TRUTH["mu0"], "a": TRUTH["a"], "b": TRUTH["b"],
                      "Dc": f"{TRUTH['Dc'] * 1e6:g} um", "noise": NOISE},
        },
    }
    return write_pair(out_dir, NAME, meta, {"t": t, "mu": mu}, 7, __name__)
