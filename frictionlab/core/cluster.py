"""Where a run's tasks go when not on the local pool: a dask.distributed cluster (``compare --scheduler``).

Every wait on a cluster is bounded, and said when it begins (``Waits``):

* connecting: the scheduler must answer distributed's handshake within ``connect`` seconds (``Client(timeout=)``
  bounds the TCP connection, not the handshake, so a server that accepts and never answers, or an HTTP server,
  would hold the client for ever: ``connect`` tries the handshake itself first, under its own deadline);
* workers: a cluster without any must get one within ``workers`` seconds, at the start and whenever its last
  worker is lost during the run;
* tasks: each task may run ``task`` seconds on its worker, where it is stopped past that (``taskhost.relay``);
  and the client ends the run when no task finishes for ``task + connect`` seconds while the cluster has workers
  (a worker that hangs, a scheduler that stops scheduling).

A scheduler lost during the run ends it at once. Each of these is one ``ClusterError`` line naming the cluster;
distributed's own log stays off the terminal (``quiet_logs``) unless asked for.
"""
from __future__ import annotations

import socket
import threading
import time
import uuid
import weakref
from concurrent.futures import Future
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Callable

from .address import check_host_port
from .errors import ClusterError, FrictionLabError, ParameterError, WorkerLost
from .taskhost import pack, pack_warm_up, relay, task_name, unpack, warm_children
from .workers import process_pool

#: Seconds the scheduler has to answer when connecting (``compare --connect-timeout``).
CONNECT_TIMEOUT = 10.0
#: Seconds to wait for a worker when the cluster has none (``compare --wait-workers``).
WAIT_WORKERS = 60.0
#: Seconds one task may run on a worker (``compare --task-timeout``): a whole dataset's fits, tests and bootstrap
#: are one task (``pipeline.perdataset``), each fit bounded by its own --fit-timeout within it.
TASK_TIMEOUT = 3600.0
#: Seconds preparing the workers for a stage may take at least (``prepare``; more when --task-timeout is longer).
PREPARE_TIMEOUT = 120.0
#: Seconds between two looks of the client at its cluster while tasks are out.
LOOK_EVERY = 0.5


@dataclass(frozen=True)
class Waits:
    """The bounds of every wait on a cluster [s], and ``say(text)``, told what each wait waits for (None: nobody)."""

    connect: float = CONNECT_TIMEOUT
    workers: float = WAIT_WORKERS
    task: float = TASK_TIMEOUT
    say: Callable[[str], None] | None = None

    def tell(self, text: str) -> None:
        if self.say is not None:
            self.say(text)


_WAITS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()  # client -> the Waits it was connected with


def waits_of(client) -> Waits:
    """The waits ``client`` was connected with (``connect``), or the defaults for a client made elsewhere."""
    try:
        return _WAITS.get(client) or Waits()
    except TypeError:  # a client that takes no weak reference
        return Waits()


def address_of(client) -> str:
    scheduler = getattr(client, "scheduler", None)
    return str(getattr(scheduler, "address", None) or "an unknown address")


@contextmanager
def executor(jobs: int, client=None, stage: str = "frictionlab", warm=None):
    """A dask.distributed ``client``'s workers (``client.get_executor``: futures of ``concurrent.futures``;
    tasks and their arguments are pickled, never hashed; each worker prepared once, ``prepare(client,
    warm)``) or, without one, ``workers.process_pool(jobs, stage)`` (None: run here). The client is the
    caller's: it stays open afterwards; on any exception the run's queued tasks are cancelled. On a worker, the
    tasks run in its child processes (``taskhost``), away from its event loop, each within the client's task time
    limit; the client watches the cluster while tasks are out (``Hosted``)."""
    if client is None:
        with process_pool(jobs, stage) as pool:
            yield pool
        return
    waits = waits_of(client)
    prepare(client, warm, waits)
    ex = Hosted(client, waits, stage)
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
    its function's name). While tasks are out, a watcher thread looks at the cluster every LOOK_EVERY seconds and
    fails every task still out with a ClusterError when the scheduler is lost, when the cluster has had no worker
    for ``waits.workers`` seconds, or when no task has finished for ``waits.task + waits.connect`` seconds."""

    def __init__(self, client, waits: Waits | None = None, stage: str = "frictionlab"):
        self._client, self._waits, self._stage = client, waits or waits_of(client), stage
        self._ex = client.get_executor(pure=False)
        self._out: dict[Future, Future] = {}  # the futures handed out -> Dask's
        self._lock = threading.Lock()
        self._stopping = False
        self._moved = time.monotonic()  # when a task last finished, or the first was sent
        self._watcher: threading.Thread | None = None

    @property
    def cluster(self) -> str:
        return f"the Dask cluster at {address_of(self._client)}"

    def submit(self, fn, *args, **kwargs) -> Future:
        key = f"{getattr(fn, '__name__', 'task')}-{uuid.uuid4().hex}"
        packed = self._ex.submit(relay, task_name(fn), pack(fn, args, kwargs), self._waits.task, key=key)
        out = Future()
        with self._lock:
            if not self._out:
                self._moved = time.monotonic()
            self._out[out] = packed
            if self._watcher is None:
                self._watcher = threading.Thread(target=self._watch, name="frictionlab-cluster-watch", daemon=True)
                self._watcher.start()
        out.add_done_callback(lambda o: o.cancelled() and packed.cancel())
        packed.add_done_callback(lambda f: self._settle(out, f, task_name(fn)))
        return out

    def _settle(self, out: Future, f: Future, name: str) -> None:
        """``out`` given ``f``'s reply unpacked (``taskhost.unpack``), or its error in one line."""
        with self._lock:
            self._out.pop(out, None)
            self._moved = time.monotonic()
        if out.done():
            return
        try:
            if f.cancelled():
                if self._stopping:
                    out.cancel()
                    out.set_running_or_notify_cancel()  # (wakes wait() and as_completed())
                    return
                raise ClusterError(f"{self.cluster}: {self._lost()}")
            if f.exception() is not None:
                raise _one_line(f.exception(), name, self.cluster)
            out.set_result(unpack(f.result()))
        except BaseException as exc:  # noqa: BLE001 (handed to whoever waits on the task)
            if not out.done():
                out.set_exception(exc)

    def _lost(self) -> str:
        return _lost(self._client, self._stage) or f"a task of {self._stage} was cancelled on the cluster"

    def _fail(self, text: str) -> None:
        """Every task still out fails with the ClusterError ``text``; its Dask future is cancelled."""
        with self._lock:
            out, self._out = dict(self._out), {}
        for mine, theirs in out.items():
            if not mine.done():
                mine.set_exception(ClusterError(f"{self.cluster}: {text}"))
            theirs.cancel()

    def _watch(self) -> None:
        """The watcher thread: see the class."""
        waits, alone_since, silent_since = self._waits, None, None
        while not self._stopping:
            time.sleep(LOOK_EVERY)
            with self._lock:
                busy, moved = bool(self._out), self._moved
            if not busy:
                alone_since = silent_since = None
                continue
            now = time.monotonic()
            if _lost(self._client):
                self._fail(self._lost())
                continue
            try:
                n = worker_count(self._client, waits.connect)
                silent_since = None
            except ClusterError:
                silent_since = silent_since or now
                if now - silent_since > waits.connect:
                    self._fail(f"the scheduler stopped answering (no reply for {waits.connect:g} s, "
                               "--connect-timeout) while tasks were out")
                continue
            if n == 0:
                if alone_since is None:
                    alone_since = now
                    waits.tell(f"{self.cluster} has no worker left: waiting up to {waits.workers:g} s for one to "
                               "join (--wait-workers)")
                elif now - alone_since > waits.workers:
                    self._fail(f"its last worker was lost and none joined within {waits.workers:g} s "
                               "(--wait-workers)")
                continue
            if alone_since is not None:
                waits.tell(f"{self.cluster}: a worker joined; the run goes on")
                alone_since, self._moved = None, now
                continue
            if now - moved > waits.task + waits.connect:
                self._fail(f"no task finished for {waits.task + waits.connect:g} s although the cluster has "
                           f"{n} worker{'s' * (n != 1)} (each task may run {waits.task:g} s, --task-timeout): a worker "
                           "or the scheduler has stopped working")

    def shutdown(self, wait: bool = True) -> None:
        """As ``Executor.shutdown``; without ``wait``, the tasks still out are cancelled."""
        self._stopping = True
        if not wait:
            with self._lock:
                out, self._out = dict(self._out), {}
            for theirs in out.values():
                theirs.cancel()
        self._ex.shutdown(wait=wait)


def _lost(client, stage: str = "frictionlab") -> str:
    """What to say when ``client`` has lost its scheduler ("" while it has it)."""
    if getattr(client, "status", "running") in ("running", "newly-created"):
        return ""
    return (f"the scheduler was lost while {stage} ran (its connection closed: killed, stopped or unreachable); "
            "the run cannot go on")


def _one_line(exc: BaseException, name: str, cluster: str) -> BaseException:
    """A task's error as the client raises it: Dask's giving up on a task whose workers kept dying as one line."""
    if type(exc).__name__ == "KilledWorker":
        return WorkerLost(f"{cluster}: the workers running {name} died one after another (killed, out of memory, or "
                          "a law plugin that ends its process); Dask gave up on the task")
    if isinstance(exc, ClusterError) and not str(exc).startswith(cluster):
        return ClusterError(f"{cluster}: {exc}")
    return exc


def worker_count(client, timeout: float) -> int:
    """The number of workers the scheduler knows now, asked within ``timeout`` seconds (ClusterError past it, or
    when the scheduler cannot be reached)."""
    try:
        info = client.sync(client.scheduler.identity, n_workers=0, callback_timeout=timeout)
    except Exception as exc:  # noqa: BLE001 (a timeout, a closed connection, a closed client)
        raise ClusterError(f"the Dask scheduler at {address_of(client)} does not answer ({_why(exc)})") from None
    n = info.get("n_workers")
    return int(n) if n is not None else len(info.get("workers", {}))


def prepare(client, warm=None, waits: Waits | None = None) -> None:
    """Once per worker process and ``warm`` function (a worker that joins later is prepared by the next run):
    its child processes started and ``warm()`` run in each (e.g. the imports every task of a stage needs, so
    no task pays them); within ``waits.task`` seconds."""
    waits = waits or waits_of(client)
    key = getattr(warm, "__qualname__", "") + "@" + getattr(warm, "__module__", "")
    cluster, limit = f"the Dask cluster at {address_of(client)}", max(waits.task, PREPARE_TIMEOUT)
    try:
        done = client.run(_prepared, key, callback_timeout=waits.connect)
    except Exception as exc:  # noqa: BLE001 (a scheduler lost or silent)
        raise ClusterError(f"{cluster}: {_lost(client) or f'the scheduler does not answer ({_why(exc)})'}") from None
    todo = [w for w, ok in done.items() if not ok]
    if not todo:
        return
    waits.tell(f"preparing {len(todo)} worker{'s' * (len(todo) != 1)} of {cluster} (starting their processes and "
               f"imports; waiting up to {limit:g} s)")
    try:
        client.run(_prepare, key, pack_warm_up(warm), workers=todo, callback_timeout=limit)
    except FrictionLabError:
        raise
    except Exception as exc:  # noqa: BLE001 (a scheduler lost or silent, a worker that died preparing)
        if _lost(client):
            raise ClusterError(f"{cluster}: {_lost(client)}") from None
        if isinstance(exc, TimeoutError) or type(exc).__name__ == "TimeoutError":
            raise ClusterError(f"{cluster}: preparing its workers took more than {limit:g} s") from None
        raise ClusterError(f"{cluster}: preparing its workers failed ({_why(exc)})") from None


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


def _why(exc: BaseException) -> str:
    """'Type: text' of an exception, on one line."""
    text = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def _usable_protocols(registry) -> list[str]:
    """The protocols a scheduler address may use here: distributed's backends that can connect (not inproc://,
    which lives within one process; not ucx:// without its package)."""
    usable = []
    for scheme in sorted(registry.backends):
        try:
            if scheme != "inproc":
                registry.get_backend(scheme).get_connector()
                usable.append(f"{scheme}://")
        except Exception:  # noqa: BLE001
            continue
    return usable


def check_address(address: str) -> tuple[str, dict]:
    """(the address with its protocol, the connection arguments) of a scheduler address, or a one-line
    ParameterError naming --scheduler: an unknown protocol, a tls:// address without certificates, a malformed host
    or port (``address.check_host_port``)."""
    try:
        from distributed.comm import registry
        from distributed.comm.addressing import parse_address
        from distributed.security import Security
    except ImportError:
        raise ParameterError("--scheduler needs dask.distributed: pip install 'frictionlab[dask]'") from None
    where = f"--scheduler {address}"
    text = address.strip()
    if not text:
        raise ParameterError("--scheduler: expected the address of a Dask scheduler, e.g. tcp://10.0.0.5:8786")
    if "://" not in text:
        text = "tcp://" + text
    known = ", ".join(_usable_protocols(registry))
    try:
        scheme, loc = parse_address(text)
    except (ValueError, TypeError) as exc:
        raise ParameterError(f"{where}: not an address a Dask scheduler listens on ({_why(exc)}); give "
                             "PROTOCOL://HOST:PORT") from None
    if f"{scheme}://" not in known:
        raise ParameterError(f"{where}: unknown or unusable protocol {scheme}://; a Dask scheduler is reached here "
                             f"through {known}")
    check_host_port(loc, where)
    try:
        args = Security().get_connection_args("client")
    except Exception as exc:  # noqa: BLE001 (certificate files named in the Dask configuration that do not load)
        raise ParameterError(f"{where}: the TLS settings of the Dask configuration do not load ({_why(exc)})") from None
    if scheme == "tls" and args.get("ssl_context") is None:
        raise ParameterError(f"{where}: a tls:// scheduler needs TLS certificates, and the Dask configuration names "
                             "none (distributed.comm.tls.ca-file, .client.cert, .client.key); set them, or use tcp://")
    return text, args


def connect(address: str, waits: Waits | None = None):
    """A dask.distributed Client of the scheduler at ``address`` (e.g. tcp://host:8786) with at least one worker,
    or a one-line error naming --scheduler; every wait bounded by ``waits`` (see the module)."""
    import asyncio

    waits = waits or Waits()
    text, args = check_address(address)
    where = f"--scheduler {address}"
    waits.tell(f"connecting to the Dask scheduler at {text} (waiting up to {waits.connect:g} s, --connect-timeout)")
    started = time.monotonic()
    try:  # first a plain connection, for the system's own word on a refusal or a name that does not resolve
        from distributed.comm.addressing import parse_address, parse_host_port

        socket.create_connection(parse_host_port(parse_address(text)[1]), timeout=waits.connect).close()
    except OSError as exc:
        raise ClusterError(f"{where}: cannot connect to a Dask scheduler there within {waits.connect:g} s "
                           f"(--connect-timeout): {exc.strerror or exc or 'timed out'}") from None
    try:
        asyncio.run(_handshake(text, max(0.5, waits.connect - (time.monotonic() - started)), args))
    except (TimeoutError, asyncio.TimeoutError):
        raise ClusterError(f"{where}: no Dask scheduler answered there within {waits.connect:g} s (--connect-timeout): "
                           "something accepts connections there but does not speak Dask's protocol, or is stuck")
    except OSError as exc:
        raise ClusterError(f"{where}: cannot connect to a Dask scheduler there within {waits.connect:g} s "
                           f"(--connect-timeout): {_why(exc)}") from None
    except Exception as exc:  # noqa: BLE001 (a server that answered something else: an HTTP server, garbage)
        raise ClusterError(f"{where}: what answered there is not a Dask scheduler ({_why(exc)})") from None
    from distributed import Client

    try:
        client = Client(text, timeout=waits.connect, set_as_default=False)
    except Exception as exc:  # noqa: BLE001 (OSError, TimeoutError, a version mismatch refused)
        raise ClusterError(f"{where}: connecting to the Dask scheduler failed ({_why(exc)})") from None
    try:
        _WAITS[client] = waits
        if worker_count(client, waits.connect) == 0:
            waits.tell(f"the Dask cluster at {text} has no workers yet: waiting up to {waits.workers:g} s for one to "
                       "join (--wait-workers)")
            try:
                client.wait_for_workers(1, timeout=waits.workers)
            except Exception:  # noqa: BLE001 (distributed's TimeoutError, or the scheduler lost meanwhile)
                raise ClusterError(f"{where}: the Dask cluster has no workers; none joined within {waits.workers:g} s "
                                   "(--wait-workers)") from None
    except BaseException:
        close(client, waits)
        raise
    return client


async def _handshake(address: str, timeout: float, args: dict) -> None:
    """Connect to ``address`` and exchange distributed's handshake, all within ``timeout`` seconds; then hang up.
    Connecting (retried while refused) may take 0.9 of it (an OSError past that), the handshake the rest (a
    TimeoutError)."""
    import asyncio

    from distributed.comm import connect as comm_connect

    comm = await asyncio.wait_for(comm_connect(address, timeout=0.9 * timeout, **args), timeout)
    await comm.close()


def close(client, waits: Waits | None = None) -> None:
    """Close ``client`` within ``waits.connect`` seconds, whatever state its scheduler is in."""
    waits = waits or waits_of(client)
    try:
        client.close(timeout=waits.connect)
    except Exception:  # noqa: BLE001 (a scheduler already gone: nothing left to close)
        pass


@contextmanager
def quiet_logs(debug: bool = False):
    """distributed's, tornado's and asyncio's loggers silenced for the block (their lines are not the user's to
    read: what matters ends as one frictionlab line), unless ``debug``."""
    import logging

    if debug:
        yield
        return
    try:
        import distributed  # noqa: F401 (its loggers exist once it is imported)
    except ImportError:
        pass
    prefixes = ("distributed", "tornado", "asyncio", "bokeh")
    loggers = [logging.getLogger(n) for n in prefixes]
    loggers += [lg for n, lg in list(logging.Logger.manager.loggerDict.items())
                if isinstance(lg, logging.Logger) and n.split(".")[0] in prefixes]
    before = [(lg, lg.disabled) for lg in loggers]
    for lg, _ in before:
        lg.disabled = True
    try:
        yield
    finally:
        for lg, was in before:
            lg.disabled = was
