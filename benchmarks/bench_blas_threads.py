"""A library call with the BLAS pool at its default size against the same call limited to one thread.

``fl.fit`` and ``fl.compare`` limit the loaded BLAS libraries to one thread for their span
(``frictionlab.core.blas``); ``fl.fit.__wrapped__`` is the same fit without the limit, as a script that imports
numpy first gets it. Run in a process whose BLAS threads the environment does not set (the command line sets
one; this benchmark clears OPENBLAS_NUM_THREADS, MKL_NUM_THREADS and OMP_NUM_THREADS and starts itself again).

Printed: per dataset and law, the CPU time and wall time of each (the median of --repeats, alternated
limited / unlimited, after one warm-up fit of each), and their ratios.

    python benchmarks/bench_blas_threads.py [--data sepiolite-velstep2,spring-slider-aging]
                                            [--laws rate-state-slip] [--repeats 3]
"""
from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS")


def timed(fn, *args):
    c, w = time.process_time(), time.perf_counter()
    fn(*args)
    return time.process_time() - c, time.perf_counter() - w


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", default="sepiolite-velstep2,spring-slider-aging")
    ap.add_argument("--laws", default="rate-state-slip")
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    if any(v in os.environ for v in THREAD_VARIABLES):
        env = {k: v for k, v in os.environ.items() if k not in THREAD_VARIABLES}
        os.execve(sys.executable, [sys.executable, *sys.argv], env)

    from threadpoolctl import threadpool_info

    import frictionlab as fl

    for name in args.data.split(","):
        try:
            data = fl.load_dataset(name)
        except fl.FrictionLabError as exc:
            print(f"{name}: skipped ({exc})")
            continue
        for law in args.laws.split(","):
            fl.fit(law, data), fl.fit.__wrapped__(law, data)  # warm: compiled kernels, imports, caches
            one, pool = [], []
            for _ in range(args.repeats):
                one.append(timed(fl.fit, law, data))
                pool.append(timed(fl.fit.__wrapped__, law, data))
            (c1, w1), (cp, wp) = [tuple(statistics.median(r[i] for r in runs) for i in (0, 1)) for runs in (one, pool)]
            print(f"{name} {law}: one BLAS thread {c1:.2f} CPU s, {w1:.2f} s wall; "
                  f"the default pool {cp:.2f} CPU s, {wp:.2f} s wall; CPU ratio {cp / c1:.2f}, wall ratio {wp / w1:.2f}")
    pools = [f"{i['internal_api']} {i['num_threads']} threads" for i in threadpool_info() if i["user_api"] == "blas"]
    print(f"BLAS libraries loaded: {', '.join(pools)}; {os.cpu_count()} CPUs")


if __name__ == "__main__":
    main()
