"""Calibration of Vuong's test (``inference.verdicts.vuong``) on synthetic velocity steps with AR(p) noise of known
coefficients: its size when both laws are equally wrong, its power when one law is true.

    python benchmarks/calibration_vuong.py [--n 40] [--n-size 80] [--seed 0] [--quick]

A one-step record like the measured basalt one (a quasi-static slider, a = 0.009, b = 0.012, k = 0.008 1/um, a
trend of 3e-6 /um; 15 s at 100 Hz before the step and 20 s after it), simulated by frictionlab's general ODE path
(LSODA), plus AR(2) noise (phi = 0.6, -0.2; innovation sigma 3e-4) drawn fresh for each replicate. Each replicate
is fitted by the aging and the slip law as a measured step is (trend and stiffness fitted, the noise model chosen
by the data: ``correlation = "arp"``), and Vuong's test (two-sided, 5 %) says which is closer. Rows:

* size: the truth is w * aging + (1 - w) * slip (Dc = 10 um for both, the x3 step), w chosen so that each law's
  best fit to the noise-free truth misses it by the same chi-square (bisection): both laws equally wrong; the
  share of replicates where the test picks a law (nominally 5 %);
* power: the aging law true, or the slip law true, at a step of x3 (3 -> 9 um/s) and of x30 (0.3 -> 9 um/s): the
  share where the test names the true law closer, and the share where it names the other (an error).

Printed: each row's share with its 95 % Wilson interval, and the CPU time. Results depend on --seed only.
``--quick`` (a smoke run): 4 replicates a row.
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import attrs
import numpy as np

from frictionlab.inference.resampling.ranking_bootstrap import wilson  # 95% Wilson score interval

sys.path.insert(0, str(Path(__file__).resolve().parent))
import velstep_records  # noqa: E402

PARAMS = {"mu0": 0.6, "a": 0.009, "b": 0.012, "Dc": 10e-6}
K_TRUE, TREND, SIGMA, AR = 8e3, 3.0, 3e-4, (0.6, -0.2)  # 1/m, 1/m (3e-6 /um), innovation sigma, AR(2)
AGING, SLIP = "rate-state-aging", "rate-state-slip"
BEFORE, AFTER, RATE, V2 = 15.0, 20.0, 100.0, 9.0


def make_dataset(folder: Path, factor: float):
    """(template dataset, x [um]) of a V2 / factor -> V2 step."""
    import frictionlab as fl

    v1 = V2 / factor
    t = np.arange(0.0, BEFORE + AFTER, 1.0 / RATE)
    x = np.where(t < BEFORE, v1 * t, v1 * BEFORE + V2 * (t - BEFORE))
    name = f"vuong-x{factor:g}"
    (folder / f"{name}.csv").write_text("t,x,mu\n" + "\n".join(f"{a:.10g},{b:.10g},0.6" for a, b in zip(t, x)) + "\n")
    (folder / f"{name}.toml").write_text(velstep_records.toml_text(
        name, "A synthetic velocity step for the calibration of Vuong's test. SYNTHETIC.", K_TRUE * 1e-6, BEFORE, v1,
        V2, 'kind = "estimated"\ncorrelation = "arp"',
        'kind = "synthetic"\nsource = "benchmarks/calibration_vuong.py"\nmethod = "the quasi-static slider (general '
        'ODE path) plus AR(2) noise of known coefficients"\ncommand = "python benchmarks/calibration_vuong.py"\n'
        "seed = 0"))
    return fl.load_dataset(folder / f"{name}.toml"), x, v1


def truth(ds, x, v1, law: str) -> np.ndarray:
    import frictionlab as fl

    return fl.simulate(law, ds, PARAMS, solver="ode:LSODA", rtol=1e-10).load + TREND * 1e-6 * (x - v1 * BEFORE)


def data_of(ds, y, correlation="arp"):
    from frictionlab.inference.fitting.predict import Target
    from frictionlab.io.noise import estimate

    cols = dict(ds.columns, mu=y)
    est = estimate(cols, "mu")
    data = attrs.evolve(ds, columns=cols, noise={"mu": est.sigma}, noise_kind="estimated", noise_est={"mu": est},
                        noise_df={"mu": est.df}, noise_correlation=correlation)
    return Target(data, "mu", y, np.full(y.size, est.sigma))


def equal_misfit(ds, aging, slip) -> float:
    """w such that the aging and slip laws' best fits to w aging + (1 - w) slip (noise-free, white weights) miss
    it by the same chi-square."""
    import frictionlab as fl

    def gap(w):
        target = data_of(ds, w * aging + (1 - w) * slip, "none")
        fa = fl.fit(AGING, target, trend=True, stiffness=True)
        fb = fl.fit(SLIP, target, trend=True, stiffness=True)
        return fa.stats.chisqr - fb.stats.chisqr  # > 0: aging misses more

    lo, hi = 0.2, 0.8
    g_lo, g_hi = gap(lo), gap(hi)
    if g_lo * g_hi > 0:
        return 0.5
    for _ in range(7):
        mid = 0.5 * (lo + hi)
        g = gap(mid)
        lo, hi, g_lo = (mid, hi, g) if g * g_lo > 0 else (lo, mid, g_lo)
    return 0.5 * (lo + hi)


def replicate(ds, curve, seed: int) -> str | None:
    """'aging', 'slip' (the test says it is closer) or '' (equally close); None where a fit fails."""
    import frictionlab as fl
    from frictionlab.inference.noise import arp
    from frictionlab.inference.verdicts.vuong import vuong

    noise = arp.draw(np.random.default_rng(seed), arp.from_coefficients(AR), curve.size, SIGMA)
    target = data_of(ds, curve + noise)
    fa = fl.fit(AGING, target, trend=True, stiffness=True)
    fb = fl.fit(SLIP, target, trend=True, stiffness=True)
    if not (fa.ok and fb.ok):
        return None
    r = vuong(fa, fb)
    return {AGING: "aging", SLIP: "slip", "": ""}[r.closer]


def row(label, ds, curve, n, seed, truth_law):
    t0 = time.process_time()
    out = [replicate(ds, curve, seed * 100003 + i) for i in range(n)]
    ok = [o for o in out if o is not None]
    picked = sum(o != "" for o in ok)
    right = sum(o == truth_law for o in ok) if truth_law else picked
    wrong = sum(o not in ("", truth_law) for o in ok) if truth_law else 0
    return {"row": label, "n": len(ok), "failed": n - len(ok), "hits": right, "wrong": wrong,
            "cpu": time.process_time() - t0}


def run(n: int, n_size: int, seed: int) -> list[dict]:
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        ds3, x3, v13 = make_dataset(Path(tmp), 3.0)
        aging3, slip3 = truth(ds3, x3, v13, AGING), truth(ds3, x3, v13, SLIP)
        w = equal_misfit(ds3, aging3, slip3)
        rows.append(row(f"size: both equally wrong (w = {w:.3f}), x3", ds3, w * aging3 + (1 - w) * slip3, n_size,
                        seed, ""))
        ds30, x30, v130 = make_dataset(Path(tmp), 30.0)
        for factor, ds, x, v1 in ((3.0, ds3, x3, v13), (30.0, ds30, x30, v130)):
            for law, short in ((AGING, "aging"), (SLIP, "slip")):
                rows.append(row(f"power: {short} true, x{factor:g}", ds, truth(ds, x, v1, law), n, seed + 1, short))
    return rows


def table(rows) -> str:
    lines = [f"{'row':<44} {'n':>4}  {'names a law closer (size) / the true law (power), %':>52}  "
             f"{'names the other, %':>18}  {'CPU s':>6}"]
    for r in rows:
        lo, hi = wilson(r["hits"], r["n"])
        share = f"{100 * r['hits'] / r['n']:5.1f} [{100 * lo:4.1f}, {100 * hi:5.1f}]"
        other = f"{100 * r['wrong'] / r['n']:5.1f}" if r["row"].startswith("power") else "—"
        lines.append(f"{r['row']:<44} {r['n']:>4}  {share:>52}  {other:>18}  {r['cpu']:>6.0f}")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=40, help="replicates of each power row")
    ap.add_argument("--n-size", type=int, default=80, help="replicates of the size row")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args(argv)
    n, n_size = (4, 4) if args.quick else (args.n, args.n_size)
    t0 = time.perf_counter()
    rows = run(n, n_size, args.seed)
    print(f"calibration_vuong: synthetic velocity steps with AR{AR} noise (seed {args.seed}); shares in %, 95% "
          "Wilson intervals in brackets; Vuong's test two-sided at 5 %")
    print(table(rows))
    print(f"({time.perf_counter() - t0:.0f} s wall)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
