"""How long the default comparison takes: every registered law on every built-in dataset, report included.

    python benchmarks/bench_compare.py [--jobs N] [--repeat R] [--keep DIR]

Prints the wall time of the fits (compare) and of writing the report, the slowest fits, and the
machine and versions. The report goes to a temporary folder unless --keep names one.
"""
from __future__ import annotations

import argparse
import os
import shutil
import statistics
import tempfile
import time
from pathlib import Path

from frictionlab import compare, write_report


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--jobs", type=int, default=min(os.cpu_count() or 1, 4))
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--keep", type=Path, help="write the last report here (replaced if it exists)")
    args = ap.parse_args()
    runs = []
    for i in range(args.repeat):
        t0 = time.perf_counter()
        c = compare(jobs=args.jobs)
        t1 = time.perf_counter()
        tmp = Path(tempfile.mkdtemp(prefix="bench-compare-"))
        out = args.keep if (args.keep and i == args.repeat - 1) else tmp / "report"
        write_report(c, out, force=True)
        t2 = time.perf_counter()
        shutil.rmtree(tmp, ignore_errors=True)
        runs.append((t1 - t0, t2 - t1))
        print(f"run {i + 1}: compare {t1 - t0:6.1f} s   report {t2 - t1:5.1f} s   total {t2 - t0:6.1f} s")
    fits = sorted((f for f in c.fits if f.ok), key=lambda f: -f.wall_time)
    print(f"\n{len(c.fits)} fits ({sum(f.ok for f in c.fits)} ok, {sum(f.status == 'failed' for f in c.fits)} failed, "
          f"{sum(f.status == 'skipped' for f in c.fits)} skipped), {len(c.equivalence)} equivalence tests, "
          f"{len(c.laws)} laws x {len(c.fitted_datasets)} datasets, jobs = {args.jobs}")
    print(f"sum of fit wall times {sum(f.wall_time for f in c.fits):.1f} s; model evaluations "
          f"{sum(f.nfev for f in c.fits)}")
    print("slowest fits:")
    for f in fits[:5]:
        print(f"  {f.wall_time:6.2f} s  {f.nfev:5d} evals  {f.law} [{f.solver}] on {f.datasets[0]}")
    if len(runs) > 1:
        print(f"median total {statistics.median(a + b for a, b in runs):.1f} s over {len(runs)} runs")
    v = c.versions
    print(f"\n{v['platform']}, {v['cpus']} CPUs; python {v['python']}, numpy {v['numpy']}, scipy {v['scipy']}, "
          f"lmfit {v['lmfit']}, matplotlib {v['matplotlib']}, frictionlab {v['frictionlab']}")


if __name__ == "__main__":
    main()
