"""Where a run's tasks go when not on the local pool: a dask.distributed cluster (``compare --scheduler``)."""
from __future__ import annotations

import ctypes
import sys
import threading
import uuid
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
    caller's: it stays open afterwards; on any exception the run's queued tasks are cancelled. While one of its
    tasks runs on a worker, that worker's profiler is stopped and its health tick and system monitor slowed
    (``quietly``)."""
    if client is None:
        with process_pool(jobs, stage) as pool:
            yield pool
        return
    prepare(client, warm)
    ex = Quiet(client.get_executor(pure=False))
    try:
        yield ex
    except BaseException:
        ex.shutdown(wait=False)
        raise
    else:
        ex.shutdown(wait=True)


class Quiet:
    """A ``client.get_executor`` whose tasks run through ``quietly`` (the task keeps its function's name)."""

    def __init__(self, ex):
        self._ex = ex

    def submit(self, fn, *args, **kwargs):
        key = f"{getattr(fn, '__name__', 'task')}-{uuid.uuid4().hex}"
        return self._ex.submit(quietly, fn, *args, key=key, **kwargs)

    def shutdown(self, wait: bool = True) -> None:
        self._ex.shutdown(wait=wait)


#: The worker's periodic callbacks that watch it, and their period (ms) while frictionlab's tasks run there
#: (None: stopped): Dask's statistical profiler (``distributed.worker.profile``), the event loop's health tick
#: (``distributed.admin.tick``, 20 ms), the system monitor (``distributed.admin.system-monitor``, 500 ms) and
#: the memory monitor (``distributed.worker.memory.monitor-interval``, 100 ms: it spills and pauses at most a
#: second later; the nanny's own monitor, which ends a worker over its memory limit, is left as it is).
QUIET = {"profile": None, "profile-cycle": None, "tick": 1000, "monitor": 5000, "memory_monitor": 1000}
#: In a worker process: how many of frictionlab's tasks run now, and (callback, its period, stopped) changed.
_STATE: dict = {"running": 0, "changed": []}
_STATE_LOCK = threading.Lock()


def quietly(fn, *args, **kwargs):
    """On a Dask worker: ``fn(*args, **kwargs)`` with the worker's callbacks in QUIET stopped or slowed while any
    of frictionlab's tasks runs there (restored as the last one ends). Each wakes the worker's event loop,
    which then takes the GIL from the computing thread at every system call: with their default periods
    a worker's compute thread was switched out about 3,000 times a second and spent 7% more CPU on the
    same fits than a plain process, its event loop 1.3 CPU s more per 33 s (``benchmarks/bench_cluster.py``;
    the profiler also walks the fits' deep stacks every 10 ms). Elsewhere (no worker), just ``fn(*args, **kwargs)``."""
    try:
        from distributed import get_worker

        worker = get_worker()
    except (ImportError, ValueError):
        return fn(*args, **kwargs)
    _count(worker, +1)
    try:
        return fn(*args, **kwargs)
    finally:
        _count(worker, -1)


def _count(worker, step: int) -> None:
    """Count a task in (+1) or out (-1); the first in quietens the worker, the last out restores it (both on
    its event loop, in the order counted: the callbacks are queued under the lock)."""
    with _STATE_LOCK:
        _STATE["running"] += step
        if _STATE["running"] == (1 if step > 0 else 0):
            worker.loop.add_callback(_quieten if step > 0 else _restore, worker)


def _quieten(worker) -> None:
    for name, period in QUIET.items():
        pc = worker.periodic_callbacks.get(name)
        if pc is None or not pc.is_running() or (period is not None and pc.callback_time >= period):
            continue
        _STATE["changed"].append((pc, pc.callback_time, period is None))
        if period is None:
            pc.stop()
        else:
            pc.callback_time = period


def _restore(worker) -> None:
    for pc, period, stopped in _STATE["changed"]:
        if stopped:
            pc.start()
        else:
            pc.callback_time = period
    _STATE["changed"] = []


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
