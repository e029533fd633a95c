"""Calibration of the segmentation of load-point displacement (``frictionlab.io.segment``) on synthetic records of
known truth: how often a stepless record is cut into pieces (false alarms), and whether the step times' and
velocities' standard errors are honest (the rms of (estimate - truth) / error near 1).

    python benchmarks/calibration_segment.py [--n 40] [--slow-tests]

Records (those of ``tests/test_segment.py``): 3000 samples 0.1 s apart. Stepless: a line at 1 um/s with white
noise (sigma 0.1 um) or AR(1) noise of coefficient 0.9 and 0.99 (innovations 0.05 um); each must be refused as
"one straight line". One step: 1 -> 3 um/s at 150 s plus a uniform offset in [0, 0.1) s, white noise (0.1 um) or
AR(1) noise of coefficient 0.9. Seeds 0 .. n - 1 (the tests' seeds). Printed per row: records, steps found where
there are none (with a 95% Wilson interval), the rms of the step time's and the velocities' z, and the CPU time.
``--slow-tests`` also runs the calibration tests the default test run leaves out (``pytest -m slow``).
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from frictionlab.core.errors import DatasetError
from frictionlab.inference.resampling.ranking_bootstrap import wilson  # 95% Wilson score interval
from frictionlab.io.segment import segment

ROOT = Path(__file__).resolve().parents[1]
T = np.arange(3000) * 0.1


def noise(rng, phi: float, white_sigma: float = 0.1, innovation: float = 0.05) -> np.ndarray:
    """White noise (phi = 0) or stationary AR(1) noise of coefficient phi [um]."""
    if phi == 0:
        return rng.normal(0.0, white_sigma, T.size)
    e = rng.normal(0.0, innovation, T.size)
    out = np.empty(T.size)
    out[0] = e[0] / np.sqrt(1 - phi * phi)
    for i in range(1, T.size):
        out[i] = phi * out[i - 1] + e[i]
    return out


def stepless(phi: float, n: int) -> str:
    cut = 0
    for seed in range(n):
        try:
            segment(T, T * 1.0 + noise(np.random.default_rng(seed), phi), "rec")
            cut += 1
        except DatasetError as exc:
            cut += "no velocity step found" not in str(exc)
    lo, hi = wilson(cut, n)
    return f"{cut} cut of {n} ({100 * cut / n:.1f} % [{100 * lo:.1f}, {100 * hi:.1f}])"


def one_step(phi: float, n: int) -> str:
    z, zv, wrong = [], [], 0
    for seed in range(n):
        rng = np.random.default_rng(seed)
        ts = 150.0 + rng.uniform(0, 0.1)
        e = noise(rng, phi)
        s = segment(T, np.where(T < ts, T, ts + 3.0 * (T - ts)) + e)
        if len(s.steps) != 1:
            wrong += 1
            continue
        z.append((s.steps[0].time - ts) / s.steps[0].time_se)
        zv += [(v - truth) / se for v, truth, se in zip(s.velocities, (1.0, 3.0), s.velocities_se)]
    rms = lambda a: float(np.sqrt(np.mean(np.square(a)))) if a else float("nan")  # noqa: E731
    return f"{n - wrong} of {n} with one step; rms z of the step time {rms(z):.2f}, of the velocities {rms(zv):.2f}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=40, help="records a row (default 40)")
    ap.add_argument("--slow-tests", action="store_true", help="also run the calibration tests marked slow")
    args = ap.parse_args()
    rows = [(f"stepless, {'white noise' if phi == 0 else f'AR(1) {phi}'}", lambda phi=phi: stepless(phi, args.n))
            for phi in (0.0, 0.9, 0.99)]
    rows += [(f"one step, {'white noise' if phi == 0 else f'AR(1) {phi}'}", lambda phi=phi: one_step(phi, args.n))
             for phi in (0.0, 0.9)]
    for name, run in rows:
        c = time.process_time()
        text = run()
        print(f"{name:28} {text}  ({time.process_time() - c:.1f} CPU s)", flush=True)
    if args.slow_tests:
        sys.exit(subprocess.call([sys.executable, "-m", "pytest", "-m", "slow", "-n", "0", "-q", "-p",
                                  "no:cacheprovider", str(ROOT / "tests" / "test_segment.py")]))


if __name__ == "__main__":
    main()
