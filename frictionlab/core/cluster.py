"""Where a run's tasks go when not on the local pool: a dask.distributed cluster (``compare --scheduler``)."""
from __future__ import annotations

import ctypes
import sys
from contextlib import contextmanager

from .errors import ParameterError
from .workers import process_pool

#: glibc's mallopt parameters, and the thresholds a prepared worker gets (bytes): arrays below MMAP_AT come
#: from the heap, and up to TRIM_AT of free memory at its top is kept for the next fit's arrays.
M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3
MMAP_AT, TRIM_AT = 32 << 20, 64 << 20


@contextmanager
def executor(jobs: int, client=None, stage: str = "frictionlab", warm=None):
    """A dask.distributed ``client``'s workers (``client.get_executor``: futures of ``concurrent.futures``;
    tasks and their arguments are pickled, never hashed; each worker prepared once, ``prepare(client,
    warm)``) or, without one, ``workers.process_pool(jobs, stage)`` (None: run here). The client is the
    caller's: it stays open afterwards; on any exception the run's queued tasks are cancelled."""
    if client is None:
        with process_pool(jobs, stage) as pool:
            yield pool
        return
    prepare(client, warm)
    ex = client.get_executor(pure=False)
    try:
        yield ex
    except BaseException:
        ex.shutdown(wait=False)
        raise
    else:
        ex.shutdown(wait=True)


def prepare(client, warm=None) -> None:
    """Once per worker process and ``warm`` function (a worker that joins later is prepared by the next run):
    ``tune_allocator`` and ``warm()`` (e.g. the imports every task of a stage needs, so no task pays them)."""
    key = getattr(warm, "__qualname__", "") + "@" + getattr(warm, "__module__", "")
    done = client.run(_prepared, key)
    todo = [w for w, ok in done.items() if not ok]
    if todo:
        client.run(_prepare, key, warm, workers=todo)


_PREPARED: set = set()  # in a worker process: the keys of the warm functions run there


def _prepared(key: str) -> bool:
    return key in _PREPARED


def _prepare(key: str, warm) -> bool:
    tune_allocator()
    if warm is not None:
        warm()
    _PREPARED.add(key)
    return True


def tune_allocator() -> None:
    """Under glibc, raise malloc's mmap and trim thresholds in this (worker) process. A Dask nanny starts
    its workers with MALLOC_TRIM_THRESHOLD_=65536, which also fixes glibc's mmap threshold at 128 KiB:
    every larger numpy array of a fit is then mapped and unmapped afresh, some 100 times the page faults
    of a plain process and about a tenth more CPU for the same fits (measured with
    ``benchmarks/bench_cluster.py``); with these thresholds those arrays stay in the heap."""
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(None)
            libc.mallopt(M_MMAP_THRESHOLD, MMAP_AT)
            libc.mallopt(M_TRIM_THRESHOLD, TRIM_AT)
        except (OSError, AttributeError):  # not glibc: its own allocator, left alone
            pass


def connect(address: str):
    """A dask.distributed Client of the scheduler at ``address`` (e.g. tcp://host:8786), or a one-line error."""
    try:
        from distributed import Client
    except ImportError:
        raise ParameterError("--scheduler needs dask.distributed: pip install 'frictionlab[dask]'") from None
    try:
        return Client(address, timeout="10s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise ParameterError(f"--scheduler {address}: cannot connect to a Dask scheduler there ({exc})") from None
