"""The process pool (or Dask cluster) every parallel stage runs on (``compare``'s fits, tests and bootstrap; the report's figures).

``process_pool(jobs)`` is a context manager yielding a ``ProcessPoolExecutor`` of ``jobs`` forked
workers, or None (run in this process) for one job or where fork is unavailable. Workers are
forked, so they see everything the parent built before the pool's first task (a function that is
not picklable can be reached through module state set before then).
"""
from __future__ import annotations

import gc
import os
import signal
import sys
import threading
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager
from multiprocessing import get_context

from .errors import Terminated

#: Allocations between two collections of the youngest generation during a long run (Python's default is
#: 700): a fit's short-lived objects are mostly freed by reference counting before a collection finds them.
GC_YOUNG = 10_000


@contextmanager
def long_run_gc(young: int = GC_YOUNG):
    """For one long command (``compare``): what is built before (modules, datasets) is frozen, so that the
    collector's full passes skip it, and the youngest generation is collected every ``young`` allocations
    (forked workers inherit both). Afterwards the thresholds are restored and, unless they were frozen
    before, the objects unfrozen. Only how often the collector runs changes, never what a run computes."""
    before, frozen = gc.get_threshold(), gc.get_freeze_count()
    gc.freeze()
    gc.set_threshold(young, *before[1:])
    try:
        yield
    finally:
        gc.set_threshold(*before)
        if not frozen:
            gc.unfreeze()


def _worker_init(parent: int) -> None:
    """In a worker: ^C goes to the parent, which stops the pool; SIGTERM ends the worker at once;
    and (on Linux) the worker gets SIGTERM when the parent dies, even by SIGKILL, so no worker
    outlives its run or keeps holding the output lock it inherited."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if sys.platform.startswith("linux"):
        try:
            import ctypes
            ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGTERM))  # 1 = PR_SET_PDEATHSIG
        except (OSError, AttributeError):
            return
        if os.getppid() != parent:  # the parent died before the request took effect
            os._exit(1)


def _on_sigterm(signum, frame):
    raise Terminated(signum)


@contextmanager
def process_pool(jobs: int):
    """A process pool of ``jobs`` forked workers, or None (run here) for one job or without fork.

    On any exception, ^C (KeyboardInterrupt) and SIGTERM included, the workers are terminated and
    reaped before the exception goes on: no worker outlives the call. SIGTERM becomes the exception
    ``errors.Terminated`` while the pool lives (when called from the main thread and nothing else
    handles SIGTERM).
    """
    try:
        ctx = get_context("fork") if jobs > 1 else None
    except ValueError:  # no fork on this platform: run serially
        ctx = None
    if ctx is None:
        yield None
        return
    handle = (threading.current_thread() is threading.main_thread()
              and signal.getsignal(signal.SIGTERM) == signal.SIG_DFL)
    if handle:
        signal.signal(signal.SIGTERM, _on_sigterm)
    # what the parent has built is shared with the forked workers: frozen, the garbage collector's full
    # passes (the workers' and the parent's) skip it instead of touching, and so copying, every page of it
    frozen = gc.get_freeze_count()  # a caller's freeze (long_run_gc) is the caller's to undo
    gc.freeze()
    pool = ProcessPoolExecutor(max_workers=jobs, mp_context=ctx, initializer=_worker_init,
                               initargs=(os.getpid(),))
    try:
        yield pool
    except BaseException:
        _stop(pool)
        raise
    else:
        pool.shutdown(wait=True)
    finally:
        if not frozen:
            gc.unfreeze()
        if handle:
            signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _stop(pool: ProcessPoolExecutor) -> None:
    """Cancel what is queued, terminate the workers (SIGTERM, then SIGKILL after 5 s) and reap them."""
    procs = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for p in procs:
        if p.is_alive():
            p.terminate()
    for p in procs:
        p.join(5)
        if p.is_alive():
            p.kill()
            p.join()
    # let the pool's manager thread finish closing its wake-up pipe now: otherwise the interpreter's
    # exit hook may race it and print "OSError: Bad file descriptor" after our one-line message
    manager = getattr(pool, "_executor_manager_thread", None)
    if manager is not None:
        manager.join(5)


@contextmanager
def executor(jobs: int, client=None):
    """Where a run's tasks go: a dask.distributed ``client``'s workers (``client.get_executor``: futures of
    ``concurrent.futures``; tasks and their arguments are pickled, never hashed) or, without one,
    ``process_pool(jobs)`` (None: run here). The client is the caller's: it stays open afterwards; on any
    exception the run's queued tasks are cancelled."""
    if client is None:
        with process_pool(jobs) as pool:
            yield pool
        return
    ex = client.get_executor(pure=False)
    try:
        yield ex
    except BaseException:
        ex.shutdown(wait=False)
        raise
    else:
        ex.shutdown(wait=True)


def connect(address: str):
    """A dask.distributed Client of the scheduler at ``address`` (e.g. tcp://host:8786), or a one-line error."""
    from .errors import ParameterError

    try:
        from distributed import Client
    except ImportError:
        raise ParameterError("--scheduler needs dask.distributed: pip install 'frictionlab[dask]'") from None
    try:
        return Client(address, timeout="10s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise ParameterError(f"--scheduler {address}: cannot connect to a Dask scheduler there ({exc})") from None
