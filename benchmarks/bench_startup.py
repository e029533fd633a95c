"""Start-up time of the command line: ``frictionlab --help`` and ``frictionlab laws`` (targets 0.3 s and 0.5 s wall).

    python benchmarks/bench_startup.py [--repeat 7]

Each command runs in a fresh interpreter (the installed ``frictionlab`` script); the output is the
median and range of the wall time and of the CPU time of the child (user + system, which other jobs on
a shared machine disturb far less), and which heavy packages each command imported.
"""
from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import time

TARGETS = {"--help": 0.3, "laws": 0.5}
HEAVY = ("numpy", "scipy", "lmfit", "matplotlib", "pandas", "pint")


def run_once(args: list[str]) -> tuple[float, float]:
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def heavy_imports(argv: list[str]) -> list[str]:
    code = ("import sys; from frictionlab.cli import main\n"
            "try:\n    main(sys.argv[1:])\nexcept SystemExit:\n    pass\n"
            f"print(','.join(m for m in {HEAVY!r} if m in sys.modules), file=sys.stderr)")
    out = subprocess.run([sys.executable, "-c", code, *argv], capture_output=True, text=True, check=True)
    last = (out.stderr.splitlines() or [""])[-1]
    return [m for m in last.split(",") if m]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    args = ap.parse_args()
    exe = shutil.which("frictionlab", path=os.path.dirname(sys.executable)) or shutil.which("frictionlab")
    base = [run_once([sys.executable, "-c", "pass"]) for _ in range(args.repeat)]
    print(f"python -c pass: wall median {statistics.median(w for w, _ in base):.3f} s (interpreter start-up)")
    for cmd, target in TARGETS.items():
        runs = [run_once([exe, cmd]) for _ in range(args.repeat)]
        walls, cpus = [w for w, _ in runs], [c for _, c in runs]
        med = statistics.median(walls)
        print(f"frictionlab {cmd:7s} wall median {med:.3f} s (range {min(walls):.3f}-{max(walls):.3f}), "
              f"CPU median {statistics.median(cpus):.3f} s; target {target} s wall: "
              f"{'met' if med <= target else 'NOT met'}; imports {', '.join(heavy_imports([cmd])) or 'none of'} "
              f"({'/'.join(HEAVY)})")
    print(f"{args.repeat} runs each; load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs "
          "(wall times on a loaded machine are upper bounds)")


if __name__ == "__main__":
    main()
