"""The same fits per CPU second in a plain process, in a Dask worker's task thread, and in its child process.

    python benchmarks/bench_worker_thread.py [--seconds 8] [--rounds 4]

Work: area-rate fitted to impact-golf-v28 again and again, counted until the computing thread has spent
``--seconds`` of CPU (``time.thread_time``: the thread's own CPU, whatever else runs in its process). Three
places, alternated ``--rounds`` times (the machine's speed drifts), each after one untimed 2 s warm-up there:
a plain Python process (started by this one); a task submitted to a LocalCluster's one worker as any Dask user
submits it (``client.submit``: it runs in the worker's task thread, next to the worker's event loop); and the
same task sent through ``core.cluster.executor``, as every task of ``compare`` and ``write_report`` on a cluster
(it runs in the worker's child process, ``core.taskhost``). Prints each round's fits and the medians, and the
ratios of the medians to the plain process's (1.00: as fast per CPU second), and the worker's and its child's
resident memory after the warm-ups.
"""
from __future__ import annotations

import argparse
import logging
import statistics
import subprocess
import sys
import time


def fits_per_cpu(seconds: float) -> int:
    """How many area-rate fits of impact-golf-v28 this thread completes in ``seconds`` of its own CPU."""
    from frictionlab.inference.fitting.fit import fit
    from frictionlab.io.dataset import load_dataset

    ds = load_dataset("impact-golf-v28")
    t0, n = time.thread_time(), 0
    while time.thread_time() - t0 < seconds:
        fit("area-rate", ds)
        n += 1
    return n


def resident() -> tuple:
    """(this process's resident memory, each child process's) in MiB."""
    import psutil

    me = psutil.Process()
    return me.memory_info().rss >> 20, [c.memory_info().rss >> 20 for c in me.children()]


def plain(seconds: float) -> int:
    out = subprocess.run([sys.executable, __file__, "--inner", str(seconds)], check=True, capture_output=True,
                         text=True).stdout
    return int(out.split()[-1])


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=8.0)
    ap.add_argument("--rounds", type=int, default=4)
    ap.add_argument("--inner", type=float, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.inner is not None:  # the plain process
        fits_per_cpu(2.0)
        print(fits_per_cpu(args.inner))
        return
    import distributed

    from frictionlab.core.cluster import executor

    logging.getLogger("distributed").setLevel(logging.ERROR)
    got = {"plain process": [], "worker's task thread": [], "worker's child process": []}
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as lc, \
            distributed.Client(lc) as client, executor(1, client) as hosted:
        client.submit(fits_per_cpu, 2.0, pure=False).result()
        hosted.submit(fits_per_cpu, 2.0).result()
        ((worker, children),) = client.run(resident).values()
        print(f"resident memory after the warm-ups: worker {worker} MiB, its child process {children} MiB")
        for r in range(args.rounds):
            got["plain process"].append(plain(args.seconds))
            got["worker's task thread"].append(client.submit(fits_per_cpu, args.seconds, pure=False).result())
            got["worker's child process"].append(hosted.submit(fits_per_cpu, args.seconds).result())
            print(f"round {r + 1}: " + ", ".join(f"{k} {v[-1]}" for k, v in got.items()), flush=True)
    med = {k: statistics.median(v) for k, v in got.items()}
    print(f"fits per {args.seconds:g} CPU s of the computing thread, medians of {args.rounds}: "
          + ", ".join(f"{k} {v:g}" for k, v in med.items()))
    for k in list(got)[1:]:
        print(f"RATIO {k} / plain process = {med[k] / med['plain process']:.3f}")


if __name__ == "__main__":
    main()
