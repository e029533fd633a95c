"""Datasets of every sample of the measured velocity-step records, made in a temporary folder for the benchmarks.

Read from the raw files at ``../shared/data/steadystate/`` beside the repository (or FRICTIONLAB_RAW_DATA), never
copied into the repository: each benchmark writes its CSV + TOML into a temporary folder and deletes it.
Conventions of the community's tools (DOMAIN.md): the step time is where the displacement changes slope, a
continuous two-line least-squares fit x = x_s + V(t) (t - t_s) (not moved to a sample), refined in a window around
the first estimate wide enough that the displacement noise is small against the slip in it; the load-point
velocities from straight-line fits of each side; a start for the stiffness from d mu/dt = k (V2 - V1) over the
first rise after the step.
"""
from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
from scipy.optimize import minimize_scalar

RECORDS = {
    "basalt-velstep4": "velstep4_BRAVA_expb819_basalt.txt",
    "sepiolite-velstep1": "velstep1_TR2_exp013_sepiolite.txt",
    "sepiolite-velstep2": "velstep2_TR2_exp013_sepiolite.txt",
    "sepiolite-velstep3": "velstep3_TR2_exp013_sepiolite.txt",
}


def raw_folder() -> Path | None:
    env = os.environ.get("FRICTIONLAB_RAW_DATA")
    folders = [Path(p) for p in env.split(os.pathsep)] if env else [Path(__file__).resolve().parents[2] / "shared" / "data"]
    for f in folders:
        if (f / "steadystate" / RECORDS["basalt-velstep4"]).is_file():
            return f / "steadystate"
    return None


def read(path):
    """(t [s], x [um], mu) of a raw record."""
    d = np.loadtxt(path, skiprows=1)
    return d[:, 0], d[:, 1], d[:, 2]


def _two_lines(t, x, ts):
    B = np.column_stack([np.ones_like(t), np.minimum(t - ts, 0.0), np.maximum(t - ts, 0.0)])
    c, *_ = np.linalg.lstsq(B, x, rcond=None)
    r = x - B @ c
    return float(r @ r), c


def kink(t, x) -> float:
    """The step time [s]: a continuous two-line fit of x(t), first over the whole record, then within a window
    around it where each side's slip is 20 times the displacement noise (at least 50 samples each side)."""
    def best(tt, xx):
        grid = np.linspace(tt[10], tt[-10], 2000)
        i = int(np.argmin([_two_lines(tt, xx, g)[0] for g in grid]))
        r = minimize_scalar(lambda s: _two_lines(tt, xx, s)[0], bounds=(grid[max(i - 2, 0)], grid[min(i + 2, 1999)]),
                            method="bounded", options={"xatol": 1e-7})
        return float(r.x)

    ts = best(t, x)
    rss, c = _two_lines(t, x, ts)
    noise = math.sqrt(rss / t.size)
    w = 20 * noise / max(min(abs(c[1]), abs(c[2])), 1e-12)
    i = int(np.searchsorted(t, ts))
    lo = min(int(np.searchsorted(t, ts - w)), i - 50)
    hi = max(int(np.searchsorted(t, ts + w)), i + 50)
    return best(t[max(lo, 0):min(hi, t.size)], x[max(lo, 0):min(hi, t.size)])


def velocities(t, x, ts) -> tuple[float, float]:
    """Load-point velocities [um/s] before and after the step: straight lines through each side."""
    before, after = t < ts, t > ts
    return float(np.polyfit(t[before], x[before], 1)[0]), float(np.polyfit(t[after], x[after], 1)[0])


def stiffness_start(t, mu, ts, v1, v2) -> float:
    """k [1/um] from d mu/dt = k (V2 - V1) over the first rise (or fall) after the step: samples until mu has
    changed by half its largest excursion in the step's direction, at least 5."""
    after = np.nonzero(t > ts)[0]
    seg = mu[after] - np.median(mu[t < ts][-50:])
    sign = 1.0 if v2 > v1 else -1.0
    top = float(np.max(sign * seg[: max(10, after.size // 10)]))
    n = max(5, int(np.argmax(sign * seg >= top / 2)) + 1)
    k = float(np.polyfit(t[after[:n]], mu[after[:n]], 1)[0]) / (v2 - v1)
    return k if k > 0 and math.isfinite(k) else 1e-3


def write(folder: Path, name: str, raw: Path, correlation: str = "ar1") -> dict:
    """Write ``name``.csv/.toml of every sample of ``raw`` into ``folder`` (its noise estimated, of the given
    ``[noise] correlation``); returns what was found."""
    t, x, mu = read(raw)
    ts = kink(t, x)
    v1, v2 = velocities(t, x, ts)
    k0 = stiffness_start(t, mu, ts, v1, v2)
    t0 = float(t[0])
    (folder / f"{name}.csv").write_text("t,x,mu\n" + "\n".join(f"{a:.10g},{b:.10g},{c:.8g}" for a, b, c in zip(t, x, mu))
                                        + "\n")
    (folder / f"{name}.toml").write_text(toml_text(
        name, f"Every sample of {raw.name} (benchmark copy in a temporary folder). MEASURED.", k0, ts - t0, v1, v2,
        f'kind = "estimated"\ncorrelation = "{correlation}"',
        f'kind = "measured"\nsource = "pgiacomel/steadystate, {raw.name} (MIT)"', time_zero=t0))
    return {"t_step": ts, "v1": v1, "v2": v2, "k0": k0, "t0": t0, "n": t.size}


def toml_text(name, description, k0, t_step, v1, v2, noise, provenance, time_zero=None) -> str:
    """The TOML of a one-step spring-slider dataset with columns t [s], x [um], mu: stiffness k0 [1/um], the step
    at t_step [s] from v1 to v2 [um/s]; ``noise`` and ``provenance`` are the lines of those tables."""
    zero = f'time_zero = "{time_zero:.10g} s"\n' if time_zero is not None else ""
    return (f'name = "{name}"\nkind = "spring-slider"\nobservable = "mu"\ndescription = "{description}"\n{zero}'
            f'[columns]\nt = "s"\nx = "um"\nmu = ""\n[noise]\n{noise}\n[scene]\nmass = "1 kg"\n'
            f'[scene.normal]\nmodel = "constant"\nvalue = "1 N"\n[scene.spring]\nstiffness = "{k0:.6g} 1/um"\n'
            f'times = ["0 s", "{t_step:.6f} s"]\nvelocities = ["{v1:.6g} um/s", "{v2:.6g} um/s"]\n'
            f'[provenance]\n{provenance}\n')
