"""On a Dask worker: frictionlab's tasks run in child processes of the worker (``relay``), one per task running.

A worker's event loop runs in the process that computes its tasks, and wakes tens of times a second
(heartbeats, monitors, messages) to take the GIL. The same fits cost about a sixth more CPU in a worker's task
thread than in a plain process: 1,487 against 1,730 area-rate fits of impact-golf-v28 per 8 CPU s of the
computing thread, and 1,736 in a child process of the same worker (medians of 4, alternated: ``python
benchmarks/bench_worker_thread.py``). A child process has no event loop. The client packs a task
(``pack``: cloudpickle); the worker's thread passes the bytes to its child over a pipe, unread, and waits
for the packed reply without holding the GIL; the client unpacks it (``unpack``). The worker never unpickles
frictionlab's objects nor imports more of it than this module.

A child starts as multiprocessing starts a spawned child of the worker (``multiprocessing.spawn.prepare``: the
worker's ``sys.path``, directory and main module, imported as ``__mp_main__``, so that laws registered there at
import are registered in the child too, as they are in the worker) with the worker's environment, less the
nanny's MALLOC_TRIM_THRESHOLD_ (so malloc behaves as in a plain process), collects garbage as ``compare``'s own process does (``long_run_gc``: what
its warm-ups built is frozen), runs every warm-up function the worker was prepared with
(``cluster.prepare``), and then one task after another. It ends with its worker (SIGKILL when the thread that
started it ends, on Linux; otherwise at the end of its pipe). A child that dies during a task (killed, out of
memory, a plugin ending its process) is the task's ``WorkerLost`` error; the next task starts another.
"""
from __future__ import annotations

import os
import pickle
import select
import subprocess
import sys
import threading

from .errors import ClusterError, FrictionLabError, WorkerLost

#: the nanny's allocator setting that a child does not inherit (it also fixes glibc's mmap threshold at 128 KiB)
NOT_INHERITED = ("MALLOC_TRIM_THRESHOLD_",)
_IDLE: list = []  # in a worker process: the children waiting for a task
_WARM: dict = {}  # in a worker process: the packed warm-ups every child runs first, by key
_LOCK = threading.Lock()


def pack(fn, args: tuple, kwargs: dict) -> bytes:
    """A task as the client sends it (cloudpickle: a function sent by value from the client, or a figure's draw
    closure, travels too)."""
    return _dumps((fn, args, kwargs))


def _dumps(obj) -> bytes:
    import cloudpickle

    return cloudpickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL)


def task_name(fn) -> str:
    """What a task is called in errors: its function's qualified name."""
    return getattr(fn, "__qualname__", None) or repr(fn)


def pack_warm_up(warm) -> bytes:
    """A warm-up for the children (``warm_children``): ``warm()`` (None: nothing), then what it built frozen."""
    return pack(_warmed, (warm,), {})


def unpack(reply: bytes):
    """A task's value from its packed reply, or its exception raised here."""
    ok, value = pickle.loads(reply)
    if ok:
        return value
    raise value


def relay(name: str, task: bytes, limit: float | None = None) -> bytes:
    """The packed ``task``'s packed reply: run in a child process when called in a Dask worker's task (the
    worker passes the bytes on, unread), here otherwise. ``name`` names the task in a ``WorkerLost`` error;
    ``limit``: seconds the task may run in the child, which is ended past it (a ``ClusterError``)."""
    if os.name != "posix" or not _on_worker():  # (no pass_fds elsewhere: in the worker's thread, as Dask runs it)
        return _replied(task)
    host = _take()
    try:
        return host.exchange(task, name, limit)
    finally:
        if host.alive():
            with _LOCK:
                _IDLE.append(host)


def _on_worker() -> bool:
    try:
        from distributed import get_worker

        get_worker()
    except (ImportError, ValueError):
        return False
    return True


def warm_children(key: str, warm: bytes, count: int) -> None:
    """In a worker: every child (at least ``count``, started now) runs the packed warm-up ``warm`` (``pack_warm_up``);
    later children run it first."""
    with _LOCK:
        _WARM[key] = warm
        idle = [h for h in _IDLE if h.alive()]
        _IDLE[:] = []
    try:
        for host in idle:
            host.warm(warm)
        idle += [_started() for _ in range(count - len(idle))]
    finally:
        with _LOCK:
            _IDLE.extend(h for h in idle if h.alive())


def _take() -> "Host":
    """An idle live child, or a new one."""
    with _LOCK:
        while _IDLE:
            host = _IDLE.pop()
            if host.alive():
                return host
    return _started()


def _started() -> "Host":
    """A new child that has run every warm-up the worker was prepared with."""
    host = Host()
    with _LOCK:
        warms = list(_WARM.values())
    for warm in warms:
        host.warm(warm)
    return host


class Host:
    """One child process and the two pipes to it."""

    def __init__(self):
        to_child, from_parent = os.pipe()
        to_parent, from_child = os.pipe()
        env = {k: v for k, v in os.environ.items() if k not in NOT_INHERITED}
        env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p)  # frictionlab found wherever the worker has it
        try:
            self.proc = subprocess.Popen(
                [sys.executable, "-m", "frictionlab.core.taskhost", str(to_child), str(from_child), str(os.getpid())],
                pass_fds=(to_child, from_child), env=env, stdin=subprocess.DEVNULL)
        finally:
            os.close(to_child)
            os.close(from_child)
        self.outbox, self.inbox = os.fdopen(from_parent, "wb"), os.fdopen(to_parent, "rb")
        from multiprocessing import spawn

        ready = {k: v for k, v in spawn.get_preparation_data("frictionlab-task-host").items() if k != "authkey"}
        self.call(spawn.prepare, (ready,), {})

    def alive(self) -> bool:
        return self.proc.poll() is None

    def warm(self, warm: bytes) -> None:
        """The packed warm-up ``warm`` (``pack_warm_up``) run in the child."""
        unpack(self.exchange(warm, "a warm-up"))

    def call(self, fn, args: tuple, kwargs: dict):
        """``fn(*args, **kwargs)`` in the child: its value, or its exception raised here."""
        return unpack(self.exchange(pack(fn, args, kwargs), task_name(fn)))

    def exchange(self, task: bytes, name: str, limit: float | None = None) -> bytes:
        """The packed ``task`` sent to the child, and its packed reply; past ``limit`` seconds the child is ended
        and ``ClusterError`` raised."""
        try:
            _send(self.outbox, task)
            # (each reply is read whole, so nothing is left buffered for select to miss)
            if limit is not None and not select.select([self.inbox], [], [], limit)[0]:
                self.proc.kill()
                self.proc.wait()
                raise ClusterError(f"task {name} ran past the task time limit of {limit:g} s on a Dask worker "
                                   "(--task-timeout); its process was ended")
            return _receive(self.inbox)
        except (EOFError, BrokenPipeError):
            self.proc.wait()
            raise WorkerLost(f"a child process of the Dask worker died while running {name} (exit status "
                             f"{self.proc.returncode}: killed, out of memory, or a law plugin that ends its "
                             "process)") from None


def _warmed(warm) -> None:
    """``warm()`` (None: nothing), then what it built frozen (``gc.freeze``)."""
    import gc

    if warm is not None:
        warm()
    gc.freeze()


def _send(f, data: bytes) -> None:
    """``data`` framed by its length."""
    f.write(len(data).to_bytes(8, "little"))
    f.write(data)
    f.flush()


def _receive(f) -> bytes:
    head = f.read(8)
    if len(head) < 8:
        raise EOFError
    size = int.from_bytes(head, "little")
    data = f.read(size)
    if len(data) < size:
        raise EOFError
    return data


def _replied(task: bytes) -> bytes:
    """The packed task run: its packed (True, value), or (False, exception) where it does not unpickle, raises,
    or its value does not pickle (then said in one line)."""
    try:
        fn, args, kwargs = pickle.loads(task)  # (a module the worker has and its child not: the task's error)
        reply = (True, fn(*args, **kwargs))
    except BaseException as exc:
        reply = (False, exc)
    try:
        return _dumps(reply)
    except Exception as exc:
        return _dumps((False, FrictionLabError(f"a task's {'value' if reply[0] else 'exception'} could not be sent "
                                               f"back from the worker's child process ({exc})")))


def _serve(inbox, outbox) -> None:
    """The child's loop: a packed task from ``inbox``, its packed reply to ``outbox``, until the pipe ends."""
    while True:
        try:
            task = _receive(inbox)
        except EOFError:
            return
        reply = _replied(task)
        del task
        try:
            _send(outbox, reply)
        except BrokenPipeError:
            return
        del reply


def main(argv: list[str]) -> int:
    """The child: its tasks run with the collector settings of ``compare``'s own process (``long_run_gc``)."""
    from .workers import _worker_init, long_run_gc

    inbox, outbox, parent = int(argv[0]), int(argv[1]), int(argv[2])
    _worker_init(parent)
    with long_run_gc():
        _serve(os.fdopen(inbox, "rb"), os.fdopen(outbox, "wb"))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
