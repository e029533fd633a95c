"""How fast the command line answers: the quick answers (``--help``, ``--version``, an unknown law, an unknown
dataset, an output folder that exists; target at most 1 CPU s each) and ``laws``, and with ``--cold`` the first
run of a fresh install against a warm one (numba's cache empty, then filled; target at most 1.3 times).

    python benchmarks/bench_startup.py [--repeat 5] [--cold "fit rate-state-aging spring-slider-aging"]

Each command runs in a fresh interpreter (the installed ``frictionlab`` script, in an empty temporary folder);
the output is the median and range of the CPU time of the child (user + system, which other jobs on a shared
machine disturb far less than the wall time) and of its wall time, and which heavy packages each command imported.
``--cold`` runs the given command with NUMBA_CACHE_DIR set to an empty folder (what a fresh install has), then
again with that folder filled, ``--repeat`` times in turn, and prints the CPU ratio first / warm.
"""
from __future__ import annotations

import argparse
import os
import resource
import shlex
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

QUICK = {"--help": ["--help"], "--version": ["--version"], "unknown law": ["fit", "no-such-law", "impact-golf-v28"],
         "unknown dataset": ["fit", "wear", "no-such-data"], "existing --out": ["compare", "--out", "exists"],
         "laws": ["laws"]}
TARGET_CPU = 1.0
HEAVY = ("numpy", "scipy", "lmfit", "matplotlib", "numba", "pandas", "pint")


def run_once(args: list[str], cwd: str, env=None) -> tuple[float, float]:
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(args, cwd=cwd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def heavy_imports(argv: list[str], cwd: str) -> list[str]:
    code = ("import sys; from frictionlab.cli import main\n"
            "try:\n    main(sys.argv[1:])\nexcept SystemExit:\n    pass\n"
            f"print(','.join(m for m in {HEAVY!r} if m in sys.modules), file=sys.stderr)")
    out = subprocess.run([sys.executable, "-c", code, *argv], capture_output=True, text=True, cwd=cwd, check=False)
    last = (out.stderr.splitlines() or [""])[-1]
    return [m for m in last.split(",") if m]


def summary(runs) -> str:
    walls, cpus = [w for w, _ in runs], [c for _, c in runs]
    return (f"CPU median {statistics.median(cpus):.2f} s (range {min(cpus):.2f}-{max(cpus):.2f}), "
            f"wall median {statistics.median(walls):.2f} s")


def cold_and_warm(exe: str, command: str, repeat: int, cwd: str) -> None:
    firsts, warms = [], []
    for _ in range(repeat):
        cache = tempfile.mkdtemp(prefix="numba-cache-")
        env = {**os.environ, "NUMBA_CACHE_DIR": cache}
        firsts.append(run_once([exe, "-q", *shlex.split(command)], cwd, env))
        warms.append(run_once([exe, "-q", *shlex.split(command)], cwd, env))
        shutil.rmtree(cache, ignore_errors=True)
    ratio = statistics.median(c for _, c in firsts) / statistics.median(c for _, c in warms)
    print(f"frictionlab {command}: first run (empty numba cache) {summary(firsts)}; warm {summary(warms)}; "
          f"first / warm CPU {ratio:.2f} (target 1.3: {'met' if ratio <= 1.3 else 'NOT met'})")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--cold", metavar="COMMAND", help="a command whose first run is compared with a warm one")
    args = ap.parse_args()
    exe = shutil.which("frictionlab", path=os.path.dirname(sys.executable)) or shutil.which("frictionlab")
    with tempfile.TemporaryDirectory() as cwd:
        os.mkdir(os.path.join(cwd, "exists"))
        base = [run_once([sys.executable, "-c", "pass"], cwd) for _ in range(args.repeat)]
        print(f"python -c pass: {summary(base)} (interpreter start-up)")
        for name, argv in QUICK.items():
            runs = [run_once([exe, *argv], cwd) for _ in range(args.repeat)]
            cpu = statistics.median(c for _, c in runs)
            print(f"frictionlab {' '.join(argv):40s} {name:16s} {summary(runs)}; target {TARGET_CPU} CPU s: "
                  f"{'met' if cpu <= TARGET_CPU else 'NOT met'}; imports {', '.join(heavy_imports(argv, cwd)) or 'none'}"
                  f" of {'/'.join(HEAVY)}")
        if args.cold:
            cold_and_warm(exe, args.cold, args.repeat, cwd)
    print(f"{args.repeat} runs each; load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs "
          "(wall times on a loaded machine are upper bounds)")


if __name__ == "__main__":
    main()
