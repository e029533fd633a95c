"""Calibration of the AR(1) noise model on synthetic velocity steps: coverage of the 95% intervals and the goodness
test's false-alarm rate, measured.

    python benchmarks/calibration_ar1.py [--n 200] [--phi 0 0.3 0.6 0.9] [--seed 0] [--quick]

A velocity step like the measured basalt one (a 3 -> 10 um/s step of a quasi-static slider, aging law, a = 0.009,
b = 0.0095, Dc = 7 um, k = 0.008 1/um, a trend of 3e-6 /um; 20 s at 100 Hz before the step and 30 s after, 5000
samples), simulated once by frictionlab's general ODE path (LSODA), plus ``n`` independent draws of AR(1) noise of
marginal sigma 8e-4 and coefficient phi per sample. Each draw is fitted as a measured step is (``fl.fit`` with the
trend and the stiffness fitted), with the dataset declaring ``correlation = "ar1"`` (the AR(1) model) and, for
comparison, ``"none"`` (independent noise). Printed per phi and model, with 95% Wilson intervals:

* coverage: the share of fits whose 95% interval (estimate ± 1.96 standard errors) holds the true a, b, Dc
  (and a - b, k); nominally 95%;
* false alarm: the share of fits of the true law that the goodness test calls a misfit (its rule: chi-square at
  the estimated sigma and the runs test, each at 0.005, so 1% family-wise);
* the mean fitted phi.

``--quick`` (for the tests): 12 draws at phi 0 and 0.6, a shorter record. Results depend on --seed only.
"""
from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
from pathlib import Path

import attrs
import numpy as np

from frictionlab.inference.resampling.ranking_bootstrap import wilson  # 95% Wilson score interval

sys.path.insert(0, str(Path(__file__).resolve().parent))
import velstep_records  # noqa: E402

TRUTH = {"mu0": 0.6, "a": 0.009, "b": 0.0095, "Dc": 7e-6}
K_TRUE, TREND, SIGMA = 8e3, 3.0, 8e-4  # 1/m, 1/m (3e-6 /um), marginal noise
LAW = "rate-state-aging"


def scenario(quick: bool):
    """(times [s], step time [s], velocities [um/s])."""
    before, after, rate = (10.0, 15.0, 100.0) if quick else (20.0, 30.0, 100.0)
    t = np.arange(0.0, before + after, 1.0 / rate)
    return t, before, (3.0, 10.0)


def make_dataset(folder: Path, correlation: str, quick: bool):
    """The template dataset (noise-free truth, trend included) and the truth curve."""
    import frictionlab as fl

    t, ts, (v1, v2) = scenario(quick)
    x = np.where(t < ts, v1 * t, v1 * ts + v2 * (t - ts))  # load-point displacement [um]
    name = f"calibration-{correlation}"
    (folder / f"{name}.csv").write_text("t,x,mu\n" + "\n".join(f"{a:.10g},{b:.10g},0.6" for a, b in zip(t, x)) + "\n")
    (folder / f"{name}.toml").write_text(velstep_records.toml_text(
        name, "A synthetic velocity step for the AR(1) calibration. SYNTHETIC.", K_TRUE * 1e-6, ts, v1, v2,
        f"kind = \"known\"\nmu = {SIGMA}",
        'kind = "synthetic"\nsource = "benchmarks/calibration_ar1.py"\nmethod = "the quasi-static slider (general '
        'ODE path) plus AR(1) noise of known coefficient"\ncommand = "python benchmarks/calibration_ar1.py"\n'
        "seed = 0"))
    ds = fl.load_dataset(folder / f"{name}.toml")
    curve = fl.simulate(LAW, ds, TRUTH, solver="ode:LSODA", rtol=1e-10).load + TREND * 1e-6 * (x - v1 * ts)
    return ds, curve


def draw(phi: float, n: int, rng) -> np.ndarray:
    e = np.empty(n)
    e[0] = rng.standard_normal()
    c = math.sqrt(1 - phi * phi)
    eps = rng.standard_normal(n)
    for i in range(1, n):
        e[i] = phi * e[i - 1] + c * eps[i]
    return SIGMA * e


def replicate(ds, curve, correlation: str, phi: float, seed: int):
    """One fit of the truth plus AR(1) noise: (covered by name, fits, fitted phi or nan)."""
    import frictionlab as fl
    from frictionlab.inference.fitting.predict import Target
    from frictionlab.io.noise import estimate

    y = curve + draw(phi, curve.size, np.random.default_rng(seed))
    cols = dict(ds.columns, mu=y)
    est = estimate(cols, "mu")
    data = attrs.evolve(ds, columns=cols, noise={"mu": est.sigma}, noise_kind="estimated", noise_est={"mu": est},
                        noise_df={"mu": est.df}, noise_correlation=correlation)
    f = fl.fit(LAW, Target(data, "mu", y, np.full(y.size, est.sigma)), trend=True, stiffness=True)
    if not f.ok:
        return None
    truth = {"a": TRUTH["a"], "b": TRUTH["b"], "a-b": TRUTH["a"] - TRUTH["b"], "Dc": TRUTH["Dc"],
             "spring.stiffness": K_TRUE}
    covered = {}
    for name, value in truth.items():
        p = f.params[name]
        covered[name] = p.stderr is not None and abs(p.value - value) <= 1.959964 * p.stderr
    phis = [p.value for p in f.params.values() if p.kind == "noise"]
    return covered, f.goodness.fits, phis[0] if phis else math.nan


def run(n: int, phis, seed: int = 0, quick: bool = False, models=("ar1", "none")) -> list[dict]:
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for model in models:
            ds, curve = make_dataset(Path(tmp), model, quick)
            for phi in phis:
                t0 = time.process_time()
                out = [replicate(ds, curve, model, phi, seed * 100003 + int(phi * 1000) * 1009 + r) for r in range(n)]
                ok = [o for o in out if o is not None]
                row = {"model": model, "phi": phi, "n": len(ok), "failed": n - len(ok),
                       "cpu": time.process_time() - t0}
                for name in ("a", "b", "a-b", "Dc", "spring.stiffness"):
                    row[name] = sum(o[0][name] for o in ok)
                row["alarms"] = sum(o[1] is False for o in ok)
                row["phi_hat"] = float(np.nanmean([o[2] for o in ok])) if model == "ar1" and ok else math.nan
                rows.append(row)
    return rows


def table(rows) -> str:
    head = (f"{'noise model':<12} {'phi':>4} {'fits':>5}  {'coverage a':>17} {'b':>17} {'a - b':>17} {'Dc':>17} "
            f"{'k':>17}  {'false alarm':>17}  {'mean phi':>8}  {'CPU s':>6}")
    lines = [head]
    for r in rows:
        cells = []
        for name in ("a", "b", "a-b", "Dc", "spring.stiffness"):
            lo, hi = wilson(r[name], r["n"])
            cells.append(f"{100 * r[name] / r['n']:5.1f} [{100 * lo:4.1f},{100 * hi:5.1f}]")
        lo, hi = wilson(r["alarms"], r["n"])
        alarm = f"{100 * r['alarms'] / r['n']:5.1f} [{100 * lo:4.1f},{100 * hi:5.1f}]"
        model = "AR(1)" if r["model"] == "ar1" else "independent"
        lines.append(f"{model:<12} {r['phi']:>4.1f} {r['n']:>5}  " + " ".join(f"{c:>17}" for c in cells)
                     + f"  {alarm:>17}  {r['phi_hat']:>8.3f}  {r['cpu']:>6.0f}")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=200)
    ap.add_argument("--phi", type=float, nargs="+", default=[0.0, 0.3, 0.6, 0.9])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args(argv)
    n, phis = (12, [0.0, 0.6]) if args.quick else (args.n, args.phi)
    t0 = time.perf_counter()
    rows = run(n, phis, args.seed, args.quick)
    print(f"calibration_ar1: {n} synthetic velocity steps per row (seed {args.seed}); coverage and false alarm in %, "
          "95% Wilson intervals in brackets")
    print(table(rows))
    print(f"({time.perf_counter() - t0:.0f} s wall)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
