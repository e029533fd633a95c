"""Calibration of the equivalence test, measured: the size and power of 'different', and how often 'equivalent
within delta' is said when the curves differ by delta or more.

    python benchmarks/calibration.py [--n 200] [--truth wear area-rate] [--noise known estimated]
                                     [--scale boundary 0.25 1 4] [--margin 1] [--jobs 2] [--seed 0] [--pivot]

Per case (truth law, noise kind, sigma as a multiple of the pair's noise threshold) it simulates ``n``
independent impacts (the paper's golf scene, 41 spin samples over the contact) from the truth, with
Gaussian noise of that sigma; with noise 'known' the dataset declares the true sigma, with 'estimated'
it declares none and sigma is estimated from the data (io/noise.py). It fits wear and area-rate and
runs ``analyze_equivalence`` (wear as A, area-rate as B). It prints, with 95% Wilson intervals:

* p(true) < alpha: the share of datasets where the true law's own p-value (p_A for wear truth, p_B for
  area-rate truth) falls below alpha = 0.05: the size of that law's test at the stated alpha, 5% if
  the p-value is calibrated;
* the share where the two-sided rule (p = 2 min(p_A, p_B) < alpha; a law is rejected when its own p is
  below alpha / 2, ``equivalence._verdict``) rejects the true law: nominally alpha / 2 = 2.5%;
* power: the share where the rule rejects the other law (its own p below alpha / 2);
* D / delta: the RMS distance of the truth's curve from the other law's best fit to it (noise-free), over
  the margin delta = margin x sigma (``--margin``, default 1 as in the library, at the true sigma);
* 'equivalent within delta': the share of datasets whose verdict is that (a test of its own, a family of
  one), and the share whose upper bound of the distance lies below delta (the bound alone, whatever the
  discrimination test says). Where D / delta >= 1 the curves differ by delta or more and either share is a
  false claim of equivalence: at most alpha = 5% if the bound is valid. The case 'boundary' puts sigma where
  D = delta exactly (the least favourable point of that null: the largest false-equivalence rate).

    python benchmarks/calibration.py --pivot   # why T is centred: T against its fitted location
    python benchmarks/calibration.py --spread --truth area-rate --scale 4 --n 80   # why a case is conservative

``--spread`` compares, for one truth and noise scale (sigma known), the spread of the data's centred
statistic over ``n`` datasets with that of its replicates (100 per dataset, drawn from each dataset's own
fit as the test draws them), and the distance c of the two laws' curves at the fitted parameters with
its value at the true ones: where the replicates spread wider than the data do, the test is conservative.

The threshold sigma* of the pair is the larger noise at which one law refitted to the other's curve
misses it by chi-square 3.84 (``EquivalenceResult.threshold``), computed per truth from its noise-free
curve. Results vary with the machine only in time; the numbers depend on --seed.
"""
from __future__ import annotations

import argparse
import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import attrs
import numpy as np

from frictionlab.inference.resampling.ranking_bootstrap import wilson  # 95% Wilson score interval

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

TRUTH = {"wear": {"lam": 1.2e6}, "area-rate": {"mu": 0.12, "eta_prime": 8000.0}}
N_POINTS = 41


def _dataset(truth: str, sigma: float, noise: str, seed: int):
    from _fit_helpers import impact_scene

    from frictionlab import Dataset, simulate
    from frictionlab.io.dataset import Provenance
    from frictionlab.io.noise import estimate

    scene = impact_scene()
    t = np.linspace(0.0, scene.duration, N_POINTS)
    y = simulate(truth, scene, TRUTH[truth], solver="exact", t=t).omega
    y = y + np.random.default_rng(seed).normal(0.0, sigma, t.size)
    cols = {"t": t, "omega": y}
    if noise == "known":
        kw = {"noise": {"omega": sigma}, "noise_kind": "known"}
    else:
        est = estimate(cols, "omega")
        kw = {"noise": {"omega": est.sigma}, "noise_kind": "estimated", "noise_df": {"omega": est.df},
              "noise_est": {"omega": est}}
    return Dataset(name=f"cal-{truth}-{seed}", kind="impact", observable="omega", path=None, columns=cols,
                   units={"t": "s", "omega": "rad/s"}, scene=scene, fixed={},
                   provenance=Provenance("synthetic", "benchmarks/calibration.py", seed=seed), **kw)


def threshold(truth: str) -> float:
    """The pair's noise threshold [rad/s] on the noise-free curve of ``truth``: the larger of the two noises at
    which one law's fit misses the other's best curve by chi-square 3.84."""
    from frictionlab import fit
    from frictionlab.inference.equivalence.discrimination import CRITICAL
    from frictionlab.inference.resampling.replicates import cross_chi2

    ds = attrs.evolve(_dataset(truth, 1e-9, "known", 0), noise={"omega": 1.0})
    fw, fa = fit("wear", ds), fit("area-rate", ds)
    return math.sqrt(max(cross_chi2(fw, fa), cross_chi2(fa, fw)) / CRITICAL)


def distance(truth: str) -> float:
    """D [rad/s]: the RMS distance of ``truth``'s noise-free curve from the other law's best fit to it."""
    from frictionlab import fit
    from frictionlab.inference.resampling.replicates import distance as rms

    ds = attrs.evolve(_dataset(truth, 1e-9, "known", 0), noise={"omega": 1.0})
    other = "area-rate" if truth == "wear" else "wear"
    fo = fit(other, ds)
    return rms(fo.per_dataset[0].target, fo.per_dataset[0].model, ds.columns["omega"])


def one(args) -> tuple:
    """(true law rejected by the rule, other law rejected by the rule, replicates drawn per null, the true
    law's one-sided p, the verdict 'equivalent within delta', the distance's bound below delta) for one
    simulated dataset."""
    truth, noise, sigma, seed, margin = args
    from frictionlab import analyze_equivalence, fit
    from frictionlab.inference.equivalence.discrimination import ALPHA, WITHIN

    ds = _dataset(truth, sigma, noise, seed)
    fw, fa = fit("wear", ds), fit("area-rate", ds)
    e = analyze_equivalence(fw, fa, seed=seed, margin=margin)
    if not e.ok:
        return False, False, 0, math.nan, False, False
    if not e.tested:  # both laws fail their fit tests: no test, no claim
        return False, False, 0, math.nan, False, False
    p_true, p_other = (e.p_a, e.p_b) if truth == "wear" else (e.p_b, e.p_a)
    # the rule rejects a law whose own p is below alpha / 2 (then p = 2 min(p_A, p_B) < alpha too)
    return (bool(p_true < ALPHA / 2), bool(p_other < ALPHA / 2), int(e.s_a.size), float(p_true),
            e.verdict == WITHIN, bool(e.p_within < ALPHA))


def pivot(truth: str, n: int) -> None:
    """Why T is centred: over ``n`` datasets of ``truth`` at the threshold noise (sigma known), the
    correlation of T = chi2(wear) - chi2(area-rate) with its location at each fitted law (the other law
    refitted to that law's best curve)."""
    from frictionlab import fit
    from frictionlab.inference.resampling.replicates import cross_chi2

    thr = threshold(truth)
    rows = []
    for i in range(n):
        ds = _dataset(truth, thr, "known", 500 + i)
        fw, fa = fit("wear", ds), fit("area-rate", ds)
        rows.append((fw.stats.chisqr - fa.stats.chisqr, cross_chi2(fw, fa), -cross_chi2(fa, fw),
                     fa.value("eta_prime") / TRUTH["area-rate"]["eta_prime"]))
    r = np.array(rows)
    print(f"{truth} truth, {n} datasets at sigma = threshold: T mean {r[:, 0].mean():.3g} sd {r[:, 0].std():.3g}; "
          f"correlation of T with its location under area-rate's fit {np.corrcoef(r[:, 0], r[:, 1])[0, 1]:.3f}, "
          f"under wear's fit {np.corrcoef(r[:, 0], r[:, 2])[0, 1]:.3f}; area-rate's fitted eta' spans "
          f"{r[:, 3].min():.2g}-{r[:, 3].max():.2g} x {TRUTH['area-rate']['eta_prime']:g}")


def _spread_one(args):
    truth, sigma, seed, m = args
    from frictionlab import fit
    from frictionlab.inference.equivalence.discrimination import _centrings
    from frictionlab.inference.resampling.replicates import refit_options, replicate_chunk, seed_sequence

    ds = _dataset(truth, sigma, "known", 7000 + seed)
    fw, fa = fit("wear", ds), fit("area-rate", ds)
    (c_a, _), (c_b, _) = _centrings(fw, fa, None, 1.0)
    t = fw.stats.chisqr - fa.stats.chisqr
    da, db = fw.per_dataset[0], fa.per_dataset[0]
    rows = np.array(replicate_chunk("wear", refit_options(fw), "area-rate", refit_options(fa), da.target, da.model,
                                    db.model, seed_sequence(seed, "spread").spawn(m)), dtype=float)
    return t, c_a, c_b, rows


def spread(truth: str, scale: float, n: int, jobs: int, m: int = 100) -> None:
    """The true law's centred statistic on ``n`` datasets against its replicates, and the two curves' distance
    (module docstring, --spread)."""
    from frictionlab import fit
    from frictionlab.inference.resampling.replicates import cross_chi2

    thr = threshold(truth)
    with ProcessPoolExecutor(jobs) as pool:
        res = list(pool.map(_spread_one, [(truth, scale * thr, i, m) for i in range(n)]))
    col = 4 if truth == "area-rate" else 1  # S_B under area-rate's fit, S_A under wear's (replicates.ROW)
    data = np.array([t - cb if truth == "area-rate" else t + ca for t, ca, cb, _ in res])
    dist = np.array([cb if truth == "area-rate" else ca for _, ca, cb, _ in res])
    reps = np.concatenate([r[np.isfinite(r).all(axis=1)] for *_, r in res])
    rep_s = reps[:, col]
    rep_c = reps[:, 3] - reps[:, 4] if truth == "area-rate" else reps[:, 1] - reps[:, 0]
    clean = attrs.evolve(_dataset(truth, 1e-9, "known", 0), noise={"omega": scale * thr})
    fw, fa = fit("wear", clean), fit("area-rate", clean)
    true_c = cross_chi2(fw, fa) if truth == "area-rate" else cross_chi2(fa, fw)
    q = [0.02, 0.05, 0.5, 0.95, 0.98]
    law = "S_B" if truth == "area-rate" else "S_A"
    print(f"{truth} truth, sigma {scale:g} x threshold, {n} datasets, {m} replicates each; quantiles {q}")
    print(f"  {law} on the data:       {np.round(np.quantile(data, q), 3)}")
    print(f"  {law} on the replicates: {np.round(np.quantile(rep_s, q), 3)}")
    print(f"  distance c of the two laws' curves [chi2]: at the true parameters {true_c:.3g}; at the data's fits "
          f"median {np.median(dist):.3g}; at the replicates' fits median {np.median(rep_c):.3g}")
    print(f"  the replicates' warm-started single-start refits against full fits (125-point scan, 3 starts), "
          f"largest chi-square difference over 18 replicates: {_refits_exact(truth, scale * thr):.2g}")


def _refits_exact(truth: str, sigma: float) -> float:
    """Largest |chi2(warm refit) - chi2(full fit)| of both laws over 6 replicates of each of 3 datasets."""
    from frictionlab import fit
    from frictionlab.inference.resampling.replicates import refit, refit_options, with_y

    worst = 0.0
    for i in range(3):
        ds = _dataset(truth, sigma, "known", 7000 + i)
        fits = {law: fit(law, ds) for law in ("wear", "area-rate")}
        own = fits[truth].per_dataset[0]
        rng = np.random.default_rng(i)
        for _ in range(6):
            tg = with_y(own.target, own.model + rng.standard_normal(own.model.size) * own.target.sigma, "replicate")
            for law, f in fits.items():
                warm = refit(law, refit_options(f), tg).stats.chisqr
                full = fit(law, tg, checks=False, errors=False).stats.chisqr
                worst = max(worst, abs(warm - full))
    return worst


def _pct(row: dict, key: str) -> str:
    lo, hi = row[key + "_ci"]
    return f"{100 * row[key]:.1f}% [{100 * lo:.1f}, {100 * hi:.1f}]"


def run(n: int, truths, noises, scales, jobs: int, seed: int, margin: float = 1.0) -> list[dict]:
    """The cases; a scale is a multiple of the pair's noise threshold, or 'boundary' (the curves' distance D
    equal to the margin delta = margin x sigma)."""
    from frictionlab.inference.equivalence.discrimination import ALPHA


    rows = []
    with ProcessPoolExecutor(jobs) as pool:
        for truth in truths:
            thr, dist = threshold(truth), distance(truth)
            print(f"noise threshold of wear vs area-rate on {truth}'s curve: {thr:.4g} rad/s "
                  f"({thr * 60 / (2 * math.pi):.4g} rpm); the curves' distance D = {dist:.4g} rad/s RMS, so D = "
                  f"delta = {margin:g} x sigma at sigma = {dist / margin / thr:.3g} x threshold", flush=True)
            for noise in noises:
                for scale in scales:
                    sigma = dist / margin if scale == "boundary" else float(scale) * thr
                    t0 = time.perf_counter()
                    tasks = [(truth, noise, sigma, seed * 100_000 + i, margin) for i in range(n)]
                    res = list(pool.map(one, tasks, chunksize=4))
                    k_size = sum(r[0] for r in res)
                    k_pow = sum(r[1] for r in res)
                    k_p = sum(r[3] < ALPHA for r in res)
                    k_eq, k_bound = sum(r[4] for r in res), sum(r[5] for r in res)
                    reps = np.mean([r[2] for r in res])
                    row = dict(truth=truth, noise=noise, scale=scale, sigma_thr=sigma / thr, margin=margin,
                               d_delta=dist / (margin * sigma), n=n, size=k_size / n, size_ci=wilson(k_size, n),
                               p_size=k_p / n, p_size_ci=wilson(k_p, n), power=k_pow / n, power_ci=wilson(k_pow, n),
                               eq=k_eq / n, eq_ci=wilson(k_eq, n), bound=k_bound / n, bound_ci=wilson(k_bound, n),
                               replicates=reps, seconds=time.perf_counter() - t0)
                    rows.append(row)
                    print(f"truth {truth:9s} noise {noise:9s} sigma {row['sigma_thr']:.3g} x threshold "
                          f"(D / delta = {row['d_delta']:.3g}): p(true) < {ALPHA:g} {_pct(row, 'p_size')}; rule rejects "
                          f"the true law {_pct(row, 'size')}, the other law (power) {_pct(row, 'power')}; 'equivalent "
                          f"within delta' {_pct(row, 'eq')}, bound below delta {_pct(row, 'bound')}; {n} datasets, mean "
                          f"{reps:.0f} replicates per null, {row['seconds']:.0f} s", flush=True)
    return rows


def table(rows: list[dict]) -> str:
    """The calibration table (Markdown): size and power of 'different', and 'equivalent within delta'."""
    head = ("| truth | noise | delta / sigma | sigma / threshold | D / delta | p(true) < 0.05 | rule rejects the true law | power | "
            "says 'equivalent within delta' | bound below delta | mean replicates per law |")
    lines = [head, "|" + "---|" * head.count(" | ") + "---|"]
    for r in rows:
        lines.append(f"| {r['truth']} | {r['noise']} | {r['margin']:g} | {r['sigma_thr']:.3g} | {r['d_delta']:.3g} | {_pct(r, 'p_size')} | "
                     f"{_pct(r, 'size')} | {_pct(r, 'power')} | {_pct(r, 'eq')} | {_pct(r, 'bound')} | "
                     f"{r['replicates']:.0f} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--n", type=int, default=200)
    p.add_argument("--truth", nargs="+", default=list(TRUTH))
    p.add_argument("--noise", nargs="+", default=["known", "estimated"])
    p.add_argument("--scale", nargs="+", default=["boundary", "0.25", "1", "4"],
                   help="sigma as a multiple of the noise threshold, or 'boundary' (the curves differ by delta exactly)")
    p.add_argument("--margin", type=float, default=1.0, help="delta as a multiple of sigma (default 1, the library's)")
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--pivot", action="store_true", help="print how T moves with the fitted parameters and stop")
    p.add_argument("--spread", action="store_true",
                   help="print the data's and the replicates' spread of the true law's statistic and stop")
    a = p.parse_args(argv)
    if a.spread:
        for truth in a.truth:
            for scale in a.scale:
                spread(truth, float(scale), a.n, a.jobs)
        return 0
    if a.pivot:
        for truth in a.truth:
            pivot(truth, 40)
        return 0
    rows = run(a.n, a.truth, a.noise, a.scale, a.jobs, a.seed, a.margin)
    print(table(rows))
    worst = max(rows, key=lambda r: r["p_size"])
    print(f"size of the true law's test at alpha = 0.05 (the largest false-rejection rate over the {len(rows)} cases run, "
          f"sup over the null): {_pct(worst, 'p_size')} ({worst['truth']} truth, noise {worst['noise']}, sigma "
          f"{worst['sigma_thr']:.3g} x threshold); the rule's: {100 * max(r['size'] for r in rows):.1f}% (nominal 2.5%)")
    apart = [r for r in rows if r["d_delta"] >= 1.0]
    if apart:
        w = max(apart, key=lambda r: (r["eq"], r["bound"]))
        print(f"'equivalent within delta' said where the curves differ by delta or more (D / delta >= 1, "
              f"{len(apart)} cases): at most {_pct(w, 'eq')} ({w['truth']} truth, noise {w['noise']}, D / delta = "
              f"{w['d_delta']:.3g}); the bound alone below delta: at most {100 * max(r['bound'] for r in apart):.1f}% "
              "(nominal at most 5%)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
