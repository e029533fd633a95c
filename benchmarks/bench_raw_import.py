"""Importing a raw velocity-step record against reading it with numpy, from 20 thousand to 2 million rows.

Run:  python benchmarks/bench_raw_import.py [--rows 20000 200000 2000000] [--steps 1 5]

Each record is written in the raw format (time, load-point displacement, friction, normal stress; samples
0.1 s apart; 0.05 um white displacement noise): one step 1 -> 10 um/s in the middle, or five steps
alternating 1 and 10 um/s. Two programs are timed, each in its own fresh process, in this one run:

* the reference: ``numpy.loadtxt`` of the record, what a user writes to read it (no step found, nothing
  written);
* ``frictionlab datasets import velstep``: the record read and checked, segmented (steps, jumps, kink times,
  velocities and their errors), every sample written as a CSV + TOML pair per step, the pair loaded back.

Printed: CPU seconds of each process (user + system, imports included), their ratio, the import's peak
resident memory, and the steps found against the truth (error over the stated standard error).
"""
from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

PROBE = ("import resource, sys, runpy\n"
         "sys.argv = {argv!r}\n"
         "{body}\n"
         "r = resource.getrusage(resource.RUSAGE_SELF)\n"
         "print('PROBE', r.ru_utime + r.ru_stime, r.ru_maxrss, file=sys.stderr)\n")


def write_record(path: Path, rows: int, steps: int) -> list[float]:
    """A record of ``rows`` samples with ``steps`` steps between 1 and 10 um/s; the step times."""
    rng = np.random.default_rng(rows + steps)
    t = np.arange(rows) * 0.1
    knots = list(t[-1] * (np.arange(1, steps + 1) / (steps + 1)) + 0.037)
    v = [1.0 if i % 2 == 0 else 10.0 for i in range(steps + 1)]
    edges = [0.0, *knots, np.inf]
    x = sum(vi * np.clip(t - a, 0.0, b - a) for a, b, vi in zip(edges[:-1], edges[1:], v))
    table = np.column_stack([t, x + rng.normal(0, 0.05, rows), 0.6 + rng.normal(0, 5e-4, rows),
                             20 + rng.normal(0, 0.01, rows)])
    with open(path, "w") as fh:
        fh.write("Time(s)\tDispl(microns)\tFriction\tEffectiveNormalstress(MPa)\n")
        np.savetxt(fh, table, fmt="%.6f", delimiter="\t")
    return knots


def probe(body: str, argv: list[str], cwd: Path) -> tuple[float, float, str]:
    """(CPU s, peak resident MiB, stdout) of ``body`` run in a fresh Python."""
    out = subprocess.run([sys.executable, "-c", PROBE.format(argv=argv, body=body)], cwd=cwd, capture_output=True,
                         text=True, timeout=3600)
    m = re.search(r"PROBE ([\d.]+) (\d+)", out.stderr)
    if out.returncode != 0 or not m:
        raise SystemExit(f"{argv}: failed ({out.returncode}):\n{out.stderr[-2000:]}")
    return float(m[1]), int(m[2]) / 1024, out.stdout


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rows", type=int, nargs="+", default=[20_000, 200_000, 2_000_000])
    ap.add_argument("--steps", type=int, nargs="+", default=[1, 5])
    args = ap.parse_args()
    import platform

    print(f"python {platform.python_version()}, numpy {np.__version__}, {platform.platform()}, {os.cpu_count()} CPUs")
    print(f"{'rows':>9} {'steps':>5} {'file MB':>8} {'loadtxt s':>10} {'import s':>9} {'ratio':>6} {'peak MiB':>9}"
          f"  steps found (|error| / standard error, largest)")
    for rows in args.rows:
        for steps in args.steps:
            with tempfile.TemporaryDirectory() as tmp:
                tmp = Path(tmp)
                truth = write_record(tmp / "rec.txt", rows, steps)
                ref, _, _ = probe("import numpy; numpy.loadtxt('rec.txt', skiprows=1)", ["loadtxt"], tmp)
                cpu, peak, out = probe("from frictionlab.cli import main; main(sys.argv[1:])",
                                       ["frictionlab", "datasets", "import", "velstep", "rec.txt", "--name", "r",
                                        "--out", "."], tmp)
                found = re.findall(r"^  \d+ +\d+ +([\d.]+) ± ([\d.]+) ", out, re.M)
                z = max((abs(float(a) - b) / float(s) for (a, s), b in zip(found, truth)), default=float("nan"))
                size = (tmp / "rec.txt").stat().st_size / 1e6
                print(f"{rows:>9} {steps:>5} {size:>8.1f} {ref:>10.2f} {cpu:>9.2f} {cpu / ref:>6.2f} {peak:>9.0f}"
                      f"  {len(found)} of {steps} ({z:.2f})")


if __name__ == "__main__":
    main()
