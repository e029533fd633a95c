"""compare on a Dask cluster: 1 and 2 worker processes against the local run, on many datasets.

    python benchmarks/bench_cluster.py [--datasets 20] [--bootstrap 40] [--rounds 2]

Workload: ``--datasets`` synthetic variants of built-in time series (impact-golf-v28, impact-golf-v61,
incline-oil-a100/a200/a400, incline-dry-d10), each the original with Gaussian noise of its stated sigma
added (seeded), under its own name and group; the four default laws, equivalence test, transfer,
tolerance check and ``--bootstrap`` replicates, then the report (its figures drawn where the fits ran).
These variants exist only to give the cluster work; they are not data.
Runs, in one process, ``--rounds`` times in this order and then again in reverse (the machine's speed drifts): the local
run with one process (``jobs=1``), a LocalCluster of 1 worker process, one of 2 worker processes (each
cluster started and its workers prepared as compare prepares them on its first run, ``core.cluster.prepare``,
before the clock starts: a cluster is long-lived), after one untimed local run on one variant of each base
(so that this process, which is the local run and every Dask run's client, has its imports and caches warm
before the first timed run, as the prepared workers have theirs).
Prints per run its wall seconds, the CPU seconds of this process (the client and, in a LocalCluster, the
scheduler) and of each worker with its child processes (where its tasks run; also apart), each worker's and its children's
resident memory at the end, and the load average (wall ratios mean something only on an idle machine:
with other work on the cores, 2 workers cannot be faster than the cores they get); then the ratios of the
median walls and, pass by pass, the 1-worker run over that pass's local run. Every run's numbers are checked equal to
the local run's.
Targets: 2 workers at least 1.6x faster than 1; 1 worker no slower than the local run.
"""
from __future__ import annotations

import argparse
import resource
import statistics
import tempfile
import time

import attrs
import numpy as np

BASES = ("impact-golf-v28", "impact-golf-v61", "incline-oil-a100", "incline-oil-a200", "incline-oil-a400",
         "incline-dry-d10")


def workload(n: int, seed: int = 7) -> list:
    from frictionlab.io.dataset import load_dataset

    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        base = load_dataset(BASES[i % len(BASES)])
        cols = dict(base.columns)
        y = cols[base.observable]
        cols[base.observable] = y + rng.normal(0.0, base.sigma, y.shape)
        name = f"{base.name}-variant{i:03d}"
        out.append(attrs.evolve(base, name=name, group=name, columns=cols, path=None))
    return out


def warm(client) -> None:
    """Prepare every worker as compare and write_report do on their first run (``core.cluster.prepare``: the
    imports a task needs, numba's cached kernel, malloc's thresholds), as a long-lived cluster has been."""
    from frictionlab.core.cluster import prepare
    from frictionlab.pipeline.runner import warm_worker
    from frictionlab.report.figures import _plt

    prepare(client, warm_worker)
    prepare(client, _plt)


def warm_here(dss) -> None:
    """One untimed local compare and report on one variant of each base: this process's imports and caches
    warm before the first timed run (the local run's; and the clients' of the Dask runs)."""
    from frictionlab.pipeline.comparison import compare
    from frictionlab.report import write_report

    with tempfile.TemporaryDirectory() as tmp:
        write_report(compare(jobs=1, datasets=dss[:len(BASES)], bootstrap=2, tolerance=(1e-3,)), f"{tmp}/r", jobs=1)


def cpu_self() -> float:
    """CPU seconds (user + system) of the calling process so far."""
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def cpu_tree() -> tuple:
    """(CPU seconds (user + system) so far of the calling process, of its live child processes): a worker's
    tasks run in its children (``core.taskhost``); the worker passes them on."""
    import psutil

    me = psutil.Process()
    return sum(me.cpu_times()[:2]), sum(sum(p.cpu_times()[:2]) for p in me.children(recursive=True))


def resident() -> tuple:
    """(the calling process's resident memory, its child processes' summed) in MiB."""
    import psutil

    me = psutil.Process()
    return me.memory_info().rss >> 20, sum(c.memory_info().rss for c in me.children(recursive=True)) >> 20


def one_run(dss, bootstrap, workers):
    """(wall seconds of compare + report, CPU seconds of this process (the client, and in a LocalCluster the
    scheduler), CPU seconds of each worker, the comparison, each worker's ``resident()`` at the end): local
    (workers None) or on a LocalCluster of ``workers`` processes."""
    from frictionlab.pipeline.comparison import compare
    from frictionlab.report import write_report

    from frictionlab.core.workers import long_run_gc

    opts = dict(datasets=dss, bootstrap=bootstrap, tolerance=(1e-3, 1e-10))
    with tempfile.TemporaryDirectory() as tmp, long_run_gc():  # as `frictionlab compare` runs, locally or not
        if workers is None:
            t0, c0 = time.perf_counter(), cpu_self()
            c = compare(jobs=1, **opts)
            write_report(c, f"{tmp}/r", jobs=1)
            return time.perf_counter() - t0, cpu_self() - c0, [], c, []
        import distributed

        with distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                      dashboard_address=None) as cluster, distributed.Client(cluster) as client:
            warm(client)
            w0 = client.run(cpu_tree)
            t0, c0 = time.perf_counter(), cpu_self()
            c = compare(client=client, **opts)
            write_report(c, f"{tmp}/r", client=client)
            wall, own = time.perf_counter() - t0, cpu_self() - c0
            w1 = client.run(cpu_tree)
            mem = client.run(resident)
            split = [(w1[k][0] - w0[k][0], w1[k][1] - w0[k][1]) for k in sorted(w0)]
            return wall, own, split, c, [mem[k] for k in sorted(mem)]


def first_difference(a, b, path="") -> str:
    """Where two results first differ (a JSON path and both values)."""
    if isinstance(a, dict) and isinstance(b, dict):
        for k in a.keys() | b.keys():
            d = first_difference(a.get(k), b.get(k), f"{path}/{k}")
            if d:
                return d
        return ""
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        return next((d for i, (x, y) in enumerate(zip(a, b)) if (d := first_difference(x, y, f"{path}[{i}]"))), "")
    return "" if a == b else f"{path}: {str(a)[:200]!r} != {str(b)[:200]!r}"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--datasets", type=int, default=20)
    ap.add_argument("--bootstrap", type=int, default=40)
    ap.add_argument("--rounds", type=int, default=2, help="rounds of the six runs (forward, then reversed)")
    args = ap.parse_args(argv)
    import logging
    import os

    logging.getLogger("distributed").setLevel(logging.ERROR)
    import sys

    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
    from test_cluster import numbers

    dss = workload(args.datasets)
    print(f"{len(dss)} datasets (synthetic variants of {', '.join(BASES)}), bootstrap {args.bootstrap}; "
          f"{os.cpu_count()} CPUs, load average at start {', '.join(f'{x:.1f}' for x in os.getloadavg())}")
    warm_here(dss)
    times = {"local": [], 1: [], 2: []}
    cpus = {"local": [], 1: [], 2: []}  # (CPU here, [CPU of each worker])
    children = {"local": [], 1: [], 2: []}  # CPU of the workers' child processes
    ref = None
    for order in (("local", 1, 2), (2, 1, "local")) * args.rounds:
        for w in order:
            t, own, split, c, mem = one_run(dss, args.bootstrap, None if w == "local" else w)
            per_worker = [a + b for a, b in split]
            times[w].append(t)
            cpus[w].append((own, per_worker))
            children[w].append(sum(b for _, b in split))
            got = numbers(c)
            ref = ref if ref is not None else got
            same = got == ref
            cpu = f"CPU {own:6.1f} s here" + (" (client and scheduler)" if per_worker else "")
            if per_worker:
                cpu += ", workers " + " + ".join(f"{x:.1f}" for x in per_worker) + f" = {sum(per_worker):.1f} s ("
                cpu += " + ".join(f"worker {a:.1f}, children {b:.1f}" for a, b in split) + ")"
                cpu += "; resident MiB (worker + its children) " + ", ".join(f"{a} + {b}" for a, b in mem)
            print(f"  {'local, 1 process' if w == 'local' else f'Dask, {w} worker process' + 'es' * (w > 1):28s} "
                  f"{t:6.1f} s wall; {cpu}; load average {os.getloadavg()[0]:.1f}; numbers "
                  f"{'equal to the first run' if same else 'DIFFER'}", flush=True)
            if not same:
                raise SystemExit("the numbers differ between runs: " + first_difference(ref, got))
    med = {k: statistics.median(v) for k, v in times.items()}
    r21, r1l = med[1] / med[2], med[1] / med["local"]
    print(f"median wall: local {med['local']:.1f} s, 1 worker {med[1]:.1f} s, 2 workers {med[2]:.1f} s")
    print(f"RATIO 1 worker / 2 workers = {r21:.2f}x (target >= 1.6: {'met' if r21 >= 1.6 else 'NOT met'})")
    print(f"RATIO 1 worker / local = {r1l:.2f} (target <= 1: {'met' if r1l <= 1.0 else 'NOT met'})")
    pairs = [a / b for a, b in zip(times[1], times["local"])]  # each pass's 1-worker run / its local run
    print(f"paired, each pass's 1-worker run / its local run: {', '.join(f'{x:.3f}' for x in pairs)} (median "
          f"{statistics.median(pairs):.3f}, {sum(x <= 1.0 for x in pairs)} of {len(pairs)} at most 1)")
    local = statistics.median(own for own, _ in cpus["local"])
    one = statistics.median(own + sum(ws) for own, ws in cpus[1])
    busiest = statistics.median(max(ws) for _, ws in cpus[2])
    print(f"CPU (what the load average does not distort as much): 1 worker and its client / local = {one / local:.2f}; "
          f"1 worker's CPU / the busier of 2 workers' = {statistics.median(sum(ws) for _, ws in cpus[1]) / busiest:.2f} "
          "(the most 2 workers can gain on 2 free cores, the client's share aside)")
    print(f"CPU of 1 worker's child process (its tasks, their unpickling and pickling) / local = "
          f"{statistics.median(children[1]) / local:.3f} (1: the tasks cost there what the whole local run costs)")
    print(f"load average at end {', '.join(f'{x:.1f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
