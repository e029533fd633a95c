"""Calibration of the data's noise model (AR(p) by BIC, ARMA(1,1) where the order runs to its cap) on synthetic
velocity steps: coverage of the 95% intervals of a, b, a - b, Dc and k, and the law-fit test's false-alarm rate,
with the noise model chosen by the fit itself. It extends ``calibration_ar1.py`` (same record) to other noise.

    python benchmarks/calibration_arp.py [--n 100] [--seed 0] [--quick]

The record of ``calibration_ar1``: a 3 -> 10 um/s step of a quasi-static slider (aging law, a = 0.009, b = 0.0095,
Dc = 7 um, k = 0.008 1/um, a trend of 3e-6 /um; 20 s at 100 Hz before the step and 30 s after, 5000 samples),
simulated once by frictionlab's general ODE path (LSODA), plus ``n`` independent draws of each noise below, scaled
to a marginal sigma of 8e-4. Each draw is fitted as a measured step is (``fl.fit`` with the trend and the
stiffness fitted) with the dataset declaring ``correlation = "arp"``. Noise: AR(2) (0.6, -0.2), AR(6)
(0.5, 0.1, -0.2, 0.1, 0.05, -0.1), ARMA(1,1) (phi 0.5, theta 0.8). Printed per noise, with 95% Wilson intervals:
the share of fits whose 95% interval holds each true value (nominally 95%), the share the law-fit test calls a
misfit (false alarm; nominally at most 1%), the models the fits chose, and the CPU time.
``--quick``: 6 draws a row.
"""
from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

import attrs
import numpy as np

from frictionlab.inference.resampling.ranking_bootstrap import wilson  # 95% Wilson score interval

sys.path.insert(0, str(Path(__file__).resolve().parent))
import calibration_ar1  # noqa: E402

NOISES = {"AR(2)": ((0.6, -0.2), 0.0), "AR(6)": ((0.5, 0.1, -0.2, 0.1, 0.05, -0.1), 0.0),
          "ARMA(1,1)": ((0.5,), 0.8)}
NAMES = ("a", "b", "a-b", "Dc", "spring.stiffness")


def replicate(ds, curve, model, seed: int):
    """(covered by name, fits, the chosen noise models) of one fit of the truth plus noise of ``model``."""
    import frictionlab as fl
    from frictionlab.inference.noise import arp
    from frictionlab.inference.fitting.predict import Target
    from frictionlab.io.noise import estimate

    sigma = calibration_ar1.SIGMA / math.sqrt(model.variance_ratio)  # innovation sigma for the marginal one
    y = curve + arp.draw(np.random.default_rng(seed), model, curve.size, sigma)
    cols = dict(ds.columns, mu=y)
    est = estimate(cols, "mu")
    data = attrs.evolve(ds, columns=cols, noise={"mu": est.sigma}, noise_kind="estimated", noise_est={"mu": est},
                        noise_df={"mu": est.df}, noise_correlation="arp")
    f = fl.fit(calibration_ar1.LAW, Target(data, "mu", y, np.full(y.size, est.sigma)), trend=True, stiffness=True)
    if not f.ok:
        return None
    t = calibration_ar1.TRUTH
    truth = {"a": t["a"], "b": t["b"], "a-b": t["a"] - t["b"], "Dc": t["Dc"], "spring.stiffness": calibration_ar1.K_TRUE}
    covered = {name: f.params[name].stderr is not None and abs(f.params[name].value - v) <= 1.959964 *
               f.params[name].stderr for name, v in truth.items()}
    chosen = ", ".join(m.split(":")[0].split(" (")[0] for _, m in f.velstep.rows[0].noise)  # "AR(1) working model"
    return covered, f.goodness.fits, chosen


def run(n: int, seed: int = 0, quick: bool = False) -> list[dict]:
    from frictionlab.inference.noise import arp

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        ds, curve = calibration_ar1.make_dataset(Path(tmp), "arp", quick)
        for i, (label, (ar, ma)) in enumerate(NOISES.items()):
            model = arp.from_coefficients(ar, ma)
            t0 = time.process_time()
            out = [replicate(ds, curve, model, seed * 100003 + i * 1009 + r) for r in range(n)]
            ok = [o for o in out if o is not None]
            row = {"noise": label, "n": len(ok), "failed": n - len(ok), "cpu": time.process_time() - t0,
                   "alarms": sum(o[1] is False for o in ok), "chosen": Counter(o[2] for o in ok)}
            for name in NAMES:
                row[name] = sum(o[0][name] for o in ok)
            rows.append(row)
    return rows


def table(rows) -> str:
    head = (f"{'noise':<10} {'fits':>5}  {'coverage a':>17} {'b':>17} {'a - b':>17} {'Dc':>17} {'k':>17}  "
            f"{'false alarm':>17}  {'CPU s':>6}  models chosen")
    lines = [head]
    for r in rows:
        cells = []
        for name in NAMES + ("alarms",):
            lo, hi = wilson(r[name], r["n"])
            cells.append(f"{100 * r[name] / r['n']:5.1f} [{100 * lo:4.1f},{100 * hi:5.1f}]")
        chosen = ", ".join(f"{m} x{c}" for m, c in r["chosen"].most_common(3))
        lines.append(f"{r['noise']:<10} {r['n']:>5}  " + " ".join(f"{c:>17}" for c in cells[:-1])
                     + f"  {cells[-1]:>17}  {r['cpu']:>6.0f}  {chosen}")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=100)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args(argv)
    n = 6 if args.quick else args.n
    t0 = time.perf_counter()
    rows = run(n, args.seed, args.quick)
    print(f"calibration_arp: {n} synthetic velocity steps per row (seed {args.seed}); coverage and false alarm in %, "
          "95% Wilson intervals in brackets; the noise model chosen by each fit")
    print(table(rows))
    print(f"({time.perf_counter() - t0:.0f} s wall)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
