"""Do the progress lines' ETAs keep their promise? Runs a command (default: a fit whose first evaluation compiles,
numba's cache empty as in a fresh install) with its progress written as plain lines, and sets each line's ETA
beside the time that was really left (the end of the run minus the line's time stamp).

    python benchmarks/bench_eta.py [--warm] [COMMAND ...]      (default: fit rate-state-aging spring-slider-aging)

Prints every ETA with the real time left and their ratio, and the largest ratio over the lines with at least
MIN_LEFT seconds left (target: at most 2, never more than twice the real time). Time stamps are whole seconds.
"""
from __future__ import annotations

import datetime as dt
import os
import re
import shutil
import subprocess
import sys
import tempfile

MIN_LEFT = 3.0
LINE = re.compile(r"^(\d{4}-\d\d-\d\d \d\d:\d\d:\d\d) .*; ETA (\d+):(\d\d):(\d\d)$")


def main() -> None:
    argv = sys.argv[1:]
    warm = "--warm" in argv
    argv = [a for a in argv if a != "--warm"] or ["fit", "rate-state-aging", "spring-slider-aging"]
    exe = shutil.which("frictionlab", path=os.path.dirname(sys.executable)) or shutil.which("frictionlab")
    cache = tempfile.mkdtemp(prefix="numba-cache-")
    env = dict(os.environ) if warm else {**os.environ, "NUMBA_CACHE_DIR": cache}
    try:
        out = subprocess.run([exe, *argv], capture_output=True, text=True, env=env, check=False)
        end = dt.datetime.now()
    finally:
        shutil.rmtree(cache, ignore_errors=True)
    ratios = []
    for line in out.stderr.splitlines():
        m = LINE.match(line)
        if not m:
            continue
        at = dt.datetime.strptime(m.group(1), "%Y-%m-%d %H:%M:%S")
        eta = 3600 * int(m.group(2)) + 60 * int(m.group(3)) + int(m.group(4))
        left = (end - at).total_seconds()
        ratio = eta / left if left > 0 else float("inf")
        print(f"{m.group(1)}  ETA {eta:6d} s  left {left:6.0f} s  ETA / left {ratio:7.2f}")
        if left >= MIN_LEFT:
            ratios.append(ratio)
    what = f"frictionlab {' '.join(argv)} ({'warm' if warm else 'numba cache empty'})"
    if not ratios:
        print(f"{what}: no ETA given with at least {MIN_LEFT:g} s left (nothing promised); exit status {out.returncode}")
        return
    worst = max(ratios)
    print(f"{what}: {len(ratios)} ETAs with at least {MIN_LEFT:g} s left; largest ETA / real time left {worst:.2f} "
          f"(target at most 2: {'met' if worst <= 2 else 'NOT met'}); exit status {out.returncode}")


if __name__ == "__main__":
    main()
