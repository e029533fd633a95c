"""Where a run's tasks go when not on the local pool: a dask.distributed cluster (``compare --scheduler``)."""
from __future__ import annotations

import uuid
from concurrent.futures import Future
from contextlib import contextmanager

from .errors import ParameterError
from .taskhost import pack, pack_warm_up, relay, task_name, unpack, warm_children
from .workers import process_pool

@contextmanager
def executor(jobs: int, client=None, stage: str = "frictionlab", warm=None):
    """A dask.distributed ``client``'s workers (``client.get_executor``: futures of ``concurrent.futures``;
    tasks and their arguments are pickled, never hashed; each worker prepared once, ``prepare(client,
    warm)``) or, without one, ``workers.process_pool(jobs, stage)`` (None: run here). The client is the
    caller's: it stays open afterwards; on any exception the run's queued tasks are cancelled. On a worker, the
    tasks run in its child processes (``taskhost``), away from its event loop."""
    if client is None:
        with process_pool(jobs, stage) as pool:
            yield pool
        return
    prepare(client, warm)
    ex = Hosted(client.get_executor(pure=False))
    try:
        yield ex
    except BaseException:
        ex.shutdown(wait=False)
        raise
    else:
        ex.shutdown(wait=True)


class Hosted:
    """A ``client.get_executor`` whose tasks run in the workers' child processes (``taskhost.relay``): each task
    pickled here, passed on unread by the scheduler and the worker, and its reply unpickled here (the task keeps
    its function's name)."""

    def __init__(self, ex):
        self._ex = ex

    def submit(self, fn, *args, **kwargs) -> Future:
        key = f"{getattr(fn, '__name__', 'task')}-{uuid.uuid4().hex}"
        return _unpacked(self._ex.submit(relay, task_name(fn), pack(fn, args, kwargs), key=key))

    def shutdown(self, wait: bool = True) -> None:
        self._ex.shutdown(wait=wait)


def _unpacked(packed: Future) -> Future:
    """A future of ``packed``'s reply unpacked (``taskhost.unpack``); cancelling either cancels both."""
    out = Future()

    def settle(f: Future) -> None:
        if f.cancelled():
            out.cancel()
            out.set_running_or_notify_cancel()  # (wakes wait() and as_completed())
        elif f.exception() is not None:
            out.set_exception(f.exception())
        else:
            try:
                out.set_result(unpack(f.result()))
            except BaseException as exc:
                out.set_exception(exc)

    out.add_done_callback(lambda o: o.cancelled() and packed.cancel())
    packed.add_done_callback(settle)
    return out


def prepare(client, warm=None) -> None:
    """Once per worker process and ``warm`` function (a worker that joins later is prepared by the next run):
    its child processes started and ``warm()`` run in each (e.g. the imports every task of a stage needs, so
    no task pays them)."""
    key = getattr(warm, "__qualname__", "") + "@" + getattr(warm, "__module__", "")
    done = client.run(_prepared, key)
    todo = [w for w, ok in done.items() if not ok]
    if todo:
        client.run(_prepare, key, pack_warm_up(warm), workers=todo)


_PREPARED: set = set()  # in a worker process: the keys of the warm functions its children run


def _prepared(key: str) -> bool:
    return key in _PREPARED


def _prepare(key: str, warm: bytes, dask_worker=None) -> bool:
    """In a worker: a child process per worker thread, each having run the packed warm-up ``warm``
    (``taskhost.warm_children``). The worker itself neither runs nor unpickles it: it only passes tasks and
    replies on, and stays as lean as Dask leaves it."""
    warm_children(key, warm, max(1, getattr(dask_worker, "nthreads", 1)))
    _PREPARED.add(key)
    return True


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
