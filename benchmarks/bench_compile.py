"""What a command spends compiling numba kernels: each compiled function's CPU seconds, and their sum against the
command's CPU time, in one process with numba's cache folder empty (a fresh install's first run).

    python benchmarks/bench_compile.py compare --jobs 1 --quiet --force --out DIR
    python benchmarks/bench_compile.py fit rate-state-aging spring-slider-aging

The command runs in this process (``frictionlab.cli.main``); numba's compile events (numba's event API,
``numba.core.event``) time each compilation, nested ones counted in the outermost. ``--jobs 1``: compilations in
worker processes are not seen. The script starts itself again with NUMBA_CACHE_DIR set to an empty temporary
folder, removed at the end.
"""
from __future__ import annotations

import collections
import os
import shutil
import subprocess
import sys
import tempfile
import time


def main() -> int:
    if "NUMBA_CACHE_DIR" not in os.environ:
        folder = tempfile.mkdtemp(prefix="frictionlab-numba-")
        try:
            env = {**os.environ, "NUMBA_CACHE_DIR": folder, "OPENBLAS_NUM_THREADS": "1"}
            return subprocess.run([sys.executable, __file__, *sys.argv[1:]], env=env).returncode
        finally:
            shutil.rmtree(folder, ignore_errors=True)
    from numba.core import event

    spent: dict[str, float] = collections.defaultdict(float)

    class Timer(event.Listener):
        def __init__(self):
            self.started: list[float] = []

        def on_start(self, ev):
            self.started.append(time.process_time())

        def on_end(self, ev):
            t0 = self.started.pop()
            if not self.started:
                fn = ev.data["dispatcher"].py_func
                spent[f"{fn.__module__}.{fn.__qualname__}"] += time.process_time() - t0

    event.register("numba:compile", Timer())
    from frictionlab import cli

    t0 = time.process_time()
    with open(os.devnull, "w") as quiet:
        stdout, sys.stdout = sys.stdout, quiet
        try:
            rc = cli.main(sys.argv[1:])
        finally:
            sys.stdout = stdout
    total = time.process_time() - t0
    for name, cpu in sorted(spent.items(), key=lambda kv: -kv[1]):
        print(f"{cpu:6.2f} CPU s  {name}")
    print(f"compiling: {sum(spent.values()):.1f} of the command's {total:.1f} CPU s (exit status {rc}; "
          f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs)")
    return rc


if __name__ == "__main__":
    sys.exit(main())
