"""The process pool every parallel stage runs on (``compare``'s fits, tests and bootstrap; the report's figures).

``process_pool(jobs)`` is a context manager yielding a ``ProcessPoolExecutor`` of ``jobs`` forked
workers, or None (run in this process) for one job or where fork is unavailable (Windows; a warning
says the run is serial). Workers are forked, so they see everything the parent built before the pool's
first task (a function that is not picklable can be reached through module state set before then); a
spawned worker would see none of it, which is why there is no spawned pool.
"""
from __future__ import annotations

import gc
import os
import signal
import sys
import threading
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
from multiprocessing import active_children, get_context

from .errors import FrictionLabError, Terminated

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


SERIAL = ("this platform cannot fork worker processes: the run is serial, in one process (--jobs has no effect; "
          "on a cluster, --scheduler runs it in parallel)")
LOST = "a worker process was lost (killed, out of memory, or a law plugin that ends its process)"


def _worker_init(parent: int) -> None:
    """In a worker: ^C goes to the parent, which stops the pool; SIGTERM ends the worker at once;
    and (on Linux) the worker gets SIGKILL when the parent dies, even by SIGKILL, so no worker
    outlives its run or keeps holding the output lock it inherited. It leads a process group of its own, which
    is ended with it, so a process a plugin forks there cannot outlive the run either."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    try:  # a process group of its own: what a plugin's code forks in it is ended with it (``_end_groups``)
        os.setpgid(0, 0)
    except OSError:
        pass
    if sys.platform.startswith("linux"):
        try:
            import ctypes
            # SIGKILL, not SIGTERM: a plugin that ignores SIGTERM cannot keep an orphaned worker alive
            ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGKILL))  # 1 = PR_SET_PDEATHSIG
        except (OSError, AttributeError):
            return
        if os.getppid() != parent:  # the parent died before the request took effect
            os._exit(1)


def _on_sigterm(signum, frame):
    raise Terminated(signum)


@contextmanager
def process_pool(jobs: int, stage: str = "frictionlab"):
    """A process pool of ``jobs`` forked workers, or None (run here) for one job, without fork, or
    where the pool cannot start (a read-only /dev/shm: a warning says so and the run goes on as --jobs 1).

    On any exception, ^C (KeyboardInterrupt) and SIGTERM included, the workers are terminated and
    reaped before the exception goes on: no worker outlives the call. SIGTERM becomes the exception
    ``errors.Terminated`` while the pool lives (when called from the main thread and nothing else
    handles SIGTERM). A worker lost (killed, out of memory, a plugin ending its process) is a
    FrictionLabError naming ``stage``.
    """
    try:
        ctx = get_context("fork") if jobs > 1 else None
    except ValueError:  # no fork on this platform: run serially, and say so
        import warnings

        warnings.warn(SERIAL, RuntimeWarning, stacklevel=3)
        ctx = None
    if ctx is None:
        try:
            yield None
        except BrokenProcessPool:  # a process of bounded() lost
            raise FrictionLabError(f"{stage}: {LOST}") from None
        return
    handle = (threading.current_thread() is threading.main_thread()
              and signal.getsignal(signal.SIGTERM) == signal.SIG_DFL)
    if handle:
        signal.signal(signal.SIGTERM, _on_sigterm)
    # what the parent has built is shared with the forked workers: frozen, the garbage collector's full
    # passes (the workers' and the parent's) skip it instead of touching, and so copying, every page of it
    frozen = gc.get_freeze_count()  # a caller's freeze (long_run_gc) is the caller's to undo
    gc.freeze()
    before = {p.pid for p in active_children()}
    pool = _start(jobs, ctx)
    try:
        yield pool
    except BrokenProcessPool:
        _stop(pool, _workers(before))
        raise FrictionLabError(f"{stage}: {LOST}") from None
    except BaseException:
        if pool is not None:
            _stop(pool, _workers(before))
        raise
    else:
        if pool is not None:
            workers = [p.pid for p in _workers(before)]
            pool.shutdown(wait=True)
            _end_groups(workers)
    finally:
        if not frozen:
            gc.unfreeze()
        if handle:
            signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _end_groups(pids) -> None:
    """End what is left of the process groups the workers ``pids`` led (processes a plugin forked there)."""
    for pid in pids:
        try:
            os.killpg(pid, signal.SIGKILL)
        except OSError:  # nothing left of it
            pass


def _start(jobs: int, ctx) -> ProcessPoolExecutor | None:
    """The pool, or None with a warning where it cannot start (no semaphores: /dev/shm read-only or missing)."""
    try:
        return ProcessPoolExecutor(max_workers=jobs, mp_context=ctx, initializer=_worker_init,
                                   initargs=(os.getpid(),))
    except (OSError, ImportError, NotImplementedError) as exc:
        import warnings

        why = getattr(exc, "strerror", None) or exc
        warnings.warn(f"cannot start worker processes ({why}; they need shared memory in /dev/shm); "
                      "running with --jobs 1", RuntimeWarning, stacklevel=4)
        return None


def _workers(before: set[int]) -> list:
    """The pool's worker processes: this process's children (``multiprocessing.active_children``) that were not
    there before the pool started (``before``: their pids)."""
    return [p for p in active_children() if p.pid not in before]


def _stop(pool: ProcessPoolExecutor, procs: list) -> None:
    """Terminate the workers ``procs`` (SIGTERM, then SIGKILL after 5 s) and reap them, then shut the pool down,
    its queued tasks cancelled: its manager thread, which sees the workers gone, ends and is waited for (else the
    interpreter's exit hook may race it and print "OSError: Bad file descriptor" after our one-line message)."""
    for p in procs:
        if p.is_alive():
            p.terminate()
    for p in procs:
        p.join(5)
        if p.is_alive():
            p.kill()
            p.join()
    _end_groups([p.pid for p in procs])
    pool.shutdown(wait=True, cancel_futures=True)


class OverBudget(Exception):
    """A call run by ``bounded`` ran past its limit; its process was ended. ``doing``: what the call said it was
    doing last (``doing``), "" if nothing."""

    def __init__(self, text: str, doing: str = ""):
        super().__init__(text)
        self.doing = doing


#: In a child of ``bounded``: the pipe to the parent, on which ``beat`` writes (None elsewhere).
_beat_fd: int | None = None


def beat() -> None:
    """In a child of ``bounded``: a new call into law code starts now, so the limit counts afresh from here
    (``fitting.fit`` beats at its start: a batch of refits in one child has the budget of one refit each).
    A no-op in any other process."""
    if _beat_fd is not None:
        os.write(_beat_fd, b"b")


def doing(text: str) -> None:
    """In a child of ``bounded``: what it does from now on (said by OverBudget if the limit passes meanwhile). A
    no-op in any other process."""
    if _beat_fd is not None:
        data = text.encode("utf-8", "replace")[:60000]
        os.write(_beat_fd, b"d" + len(data).to_bytes(2, "little") + data)


def bounded(fn, limit: float, *args):
    """``fn(*args)`` run in a forked child process that is ended (SIGKILL) once it has run ``limit``
    seconds since it started or last called ``beat``: a time budget enforced from outside the code it
    bounds (a plugin's ``except:`` cannot keep it). The result or the exception comes back pickled, framed
    by its length, so a process the child forked (a plugin's helper, which inherits the pipe) cannot hold
    the answer back; the child leads its own process group, which is ended with it, helpers included.
    OverBudget past the limit; BrokenProcessPool if the child died without a result. Runs here where
    there is no fork."""
    import pickle

    if not hasattr(os, "fork"):
        return fn(*args)
    read, write = os.pipe()
    with _quiet_fork():
        pid = os.fork()
    if pid == 0:  # the child: never returns into the caller's code
        _child(read, write, fn, args)
    os.close(write)
    try:
        payload = _receive(read, limit)
    finally:
        os.close(read)
        _end(pid)
    if payload is None:  # the child died (killed, or a plugin's os._exit): as a pool's lost worker
        raise BrokenProcessPool("the process running it ended without a result")
    ok, value = pickle.loads(payload)
    if ok:
        return value
    raise value


def _child(read: int, write: int, fn, args) -> None:
    """The child of ``bounded``: run, send b'r' and the pickled outcome, and exit (never returns)."""
    global _beat_fd
    import pickle

    status = 0
    try:
        os.close(read)
        _worker_init(os.getppid())  # (a process group of its own: ended with it, helpers included, by _end)
        _beat_fd = write
        try:
            payload = pickle.dumps((True, fn(*args)))
        except BaseException as exc:  # noqa: BLE001 (sent back as it is)
            payload = _pickled_error(exc)
        os.write(write, b"r")
        with os.fdopen(write, "wb") as fh:
            fh.write(len(payload).to_bytes(8, "little") + payload)
    except BaseException:  # noqa: BLE001
        status = 1
    finally:
        os._exit(status)


def _receive(read: int, limit: float) -> bytes | None:
    """What the child sends after b'r': an 8-byte length and that many bytes (None if the pipe ends first);
    each b'b' before it restarts the limit, each b'd' says what it does (``doing``). Returns once the answer is
    whole, never waiting for the pipe to end."""
    import select
    import time

    got, deadline, started, now_doing = bytearray(), time.monotonic() + limit, False, ""
    while True:
        while not started and got:  # the messages before the answer: b'b', b'd' + 2-byte length + text, b'r'
            if got[:1] == b"b":
                deadline, got = time.monotonic() + limit, got[1:]
            elif got[:1] == b"d":
                if len(got) < 3 or len(got) < 3 + int.from_bytes(got[1:3], "little"):
                    break
                n = int.from_bytes(got[1:3], "little")
                now_doing, got = bytes(got[3:3 + n]).decode("utf-8", "replace"), got[3 + n:]
            else:  # b'r'
                started, got = True, got[1:]
        if started and len(got) >= 8 and len(got) >= 8 + int.from_bytes(got[:8], "little"):
            return bytes(got[8:8 + int.from_bytes(got[:8], "little")])
        left = deadline - time.monotonic()
        if left <= 0 or not select.select([read], [], [], left)[0]:
            raise OverBudget(f"ran past {limit:g} s", now_doing)
        chunk = os.read(read, 1 << 16)
        if not chunk:
            return None
        got += chunk


def _pickled_error(exc: BaseException) -> bytes:
    import pickle

    try:
        return pickle.dumps((False, exc))
    except Exception:  # an exception that does not pickle: its type and text
        return pickle.dumps((False, RuntimeError(f"{type(exc).__name__}: {exc}")))


def _end(pid: int) -> None:
    """Kill the child ``pid`` and what is left of its process group (helpers its code forked), and reap it."""
    try:
        os.killpg(pid, signal.SIGKILL)
    except OSError:  # the group is empty, or the child could not lead one
        pass
    try:
        done, _ = os.waitpid(pid, os.WNOHANG)
        if not done:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
    except ChildProcessError:
        pass


@contextmanager
def _quiet_fork():
    """Python warns when a process with threads forks; the child here only computes and exits."""
    import warnings

    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", category=DeprecationWarning, message=".*fork.*")
        yield
