"""One BLAS thread while frictionlab computes.

frictionlab's linear algebra is many small products on one record at a time (a dot product of a 75,000-sample
residual, a 5-column Jacobian), where waking a BLAS pool's threads costs far more than it saves: a
velocity-step fit of sepiolite-velstep2 took 3.8 CPU s and 3.7 s wall with OpenBLAS's two threads on a 2-core
machine, and 1.2 CPU s and 1.3 s wall with one (``python benchmarks/bench_blas_threads.py``). The command line sets
one thread before numpy loads (``cli.blas_one_thread``); a library call (``fit``, ``compare``,
``analyze_equivalence``, ``load_dataset``) limits the BLAS libraries already loaded to one thread for its
duration through threadpoolctl's public API, and gives the caller's setting back when it returns.
"""
from __future__ import annotations

import functools
import threading

_depth = threading.local()


def one_blas_thread(fn):
    """``fn`` run with the loaded BLAS libraries limited to one thread (the outermost call in a thread sets the
    limit and restores the caller's setting; a nested call runs as it finds them)."""

    @functools.wraps(fn)
    def limited(*args, **kwargs):
        if getattr(_depth, "n", 0):
            return fn(*args, **kwargs)
        from threadpoolctl import threadpool_limits

        _depth.n = 1
        try:
            with threadpool_limits(limits=1, user_api="blas"):
                return fn(*args, **kwargs)
        finally:
            _depth.n = 0

    return limited
