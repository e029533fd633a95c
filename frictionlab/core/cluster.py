"""Where a run's tasks go when not on the local pool: a dask.distributed cluster (``compare --scheduler``)."""
from __future__ import annotations

from contextlib import contextmanager

from .errors import ParameterError
from .workers import process_pool


@contextmanager
def executor(jobs: int, client=None, stage: str = "frictionlab"):
    """A dask.distributed ``client``'s workers (``client.get_executor``: futures of ``concurrent.futures``;
    tasks and their arguments are pickled, never hashed) or, without one, ``workers.process_pool(jobs,
    stage)`` (None: run here). The client is the caller's: it stays open afterwards; on any exception the
    run's queued tasks are cancelled."""
    if client is None:
        with process_pool(jobs, stage) as pool:
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
    try:
        from distributed import Client
    except ImportError:
        raise ParameterError("--scheduler needs dask.distributed: pip install 'frictionlab[dask]'") from None
    try:
        return Client(address, timeout="10s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise ParameterError(f"--scheduler {address}: cannot connect to a Dask scheduler there ({exc})") from None
