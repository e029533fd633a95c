"""'Spin from rotation angle': theta -> omega by each route, on the column as given and with simulated noise."""
from __future__ import annotations

import math

import numpy as np

from ..core.display import fmt, unit
from ..physics.derive import METHODS, derive_omega
from . import figures
from .doc import Section

TITLE = "Spin from rotation angle"
DERIVE_SEED = 0


def derivations(ds):
    """theta -> omega by each route: on the column as given, and with simulated noise of the stated sigma."""
    sigma = ds.noise.get("theta")
    rng = np.random.default_rng(DERIVE_SEED)
    noisy_theta = ds.columns["theta"] + rng.normal(0.0, sigma or 0.0, len(ds))
    given = {m: derive_omega(ds.t, ds.columns["theta"], m, sigma) for m in METHODS}
    noisy = {m: derive_omega(ds.t, noisy_theta, m, sigma) for m in METHODS}
    noisy["_theta"] = noisy_theta
    return given, noisy, sigma


def derivation_stats(ds, given, noisy) -> dict:
    ref = ds.columns.get("omega")
    out = {}
    for m, d in given.items():
        rms = lambda x: float(np.sqrt(np.mean((x - ref) ** 2))) if ref is not None else math.nan  # noqa: E731
        out[m] = {"rms_vs_omega_column": rms(d.omega), "omega_peak": float(np.max(d.omega)),
                  "omega_end": float(d.omega[-1]), "noisy_median_sigma": float(np.median(noisy[m].sigma)),
                  "noisy_rms_vs_omega_column": rms(noisy[m].omega), "noisy_omega_peak": float(np.max(noisy[m].omega)),
                  "noisy_omega_end": float(noisy[m].omega[-1])}
    return out


def build(ctx) -> Section | None:
    c = ctx.c
    fitted = c.fitted_datasets
    sec = Section(TITLE)
    with_theta = [d for d in fitted if "theta" in d.columns and "t" in d.columns]
    if not with_theta:
        return None
    sec.p("Cameras record the rotation angle θ(t), not the spin ω(t). frictionlab can fit θ directly "
          "(`frictionlab fit LAW DATASET --observable theta`), or derive ω first: by the paper's route, a "
          "9th-order polynomial of θ differentiated (`--derive poly9`), or by a cubic smoothing spline with a "
          "penalty chosen by generalized cross-validation (`--derive spline`). The figures show each route on "
          "the θ column as given, and on the same column with simulated camera noise of the dataset's stated "
          f"σθ (seed {DERIVE_SEED}), which is what real frames carry; the shaded bands are the ±1σ that each "
          "route passes on to ω.")
    for d in with_theta:
        given, noisy, sigma = derivations(d)
        stats = derivation_stats(d, given, noisy)
        ctx.json.setdefault("derivations", {})[d.name] = stats
        sec.h3(d.name)
        sec.fig(f"derive-{d.name}.png", f"{d.name}: ω derived from θ by poly9 and spline, " + (
                "without and with simulated noise." if sigma else "on the column as given (no θ noise stated)."), lambda d=d, given=given, noisy=noisy, sigma=sigma:
                figures.derivation_figure(d, given, noisy, sigma or 0.0, DERIVE_SEED))
        uname, uf = unit("omega")
        sec.table(["route", f"RMS vs ω column [{uname}]", f"peak [{uname}]", f"end [{uname}]",
                   f"with noise: RMS vs ω column [{uname}]", f"with noise: peak [{uname}]",
                   f"with noise: end [{uname}]", f"with noise: median ±1σ passed on [{uname}]"],
                  [[m, fmt(s["rms_vs_omega_column"] * uf), fmt(s["omega_peak"] * uf), fmt(s["omega_end"] * uf),
                    fmt(s["noisy_rms_vs_omega_column"] * uf), fmt(s["noisy_omega_peak"] * uf),
                    fmt(s["noisy_omega_end"] * uf), fmt(s["noisy_median_sigma"] * uf)] for m, s in stats.items()])
        ref = d.reported
        if ref:
            sec.p("Reported in the paper for this impact: " + ", ".join(f"{k} = {v}" for k, v in ref.items()
                                                                       if "omega" in k or k == "t_peak") + ".")
    return sec
