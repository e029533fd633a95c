"""A Dask cluster on 127.0.0.1 whose scheduler and workers are separate processes, each killable by its pid
(``dask scheduler`` and ``dask worker --no-nanny``, so a killed worker stays dead), and two servers that are
not Dask schedulers: one that accepts connections and never answers, and an HTTP server."""
from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import threading
import time
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Processes:
    """The scheduler and workers started for one test; ``stop()`` ends every one still running (by its pid)."""

    def __init__(self, folder, env=None):
        self.folder, self.procs, self.address, self.env = folder, [], None, env

    def _start(self, module: str, *args: str) -> subprocess.Popen:
        log = open(os.path.join(self.folder, f"dask-{len(self.procs)}.log"), "wb")
        proc = subprocess.Popen([sys.executable, "-m", f"distributed.cli.{module}", *args], stdout=log,
                                stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, cwd=self.folder,
                                env=self.env)
        log.close()
        self.procs.append(proc)
        return proc

    def scheduler(self) -> str:
        port = free_port()
        self.sched = self._start("dask_scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard",
                                 "--no-show")
        self.address = f"tcp://127.0.0.1:{port}"
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:  # up once it accepts connections
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                return self.address
            except OSError:
                if self.sched.poll() is not None:
                    break
                time.sleep(0.2)
        raise RuntimeError(f"the Dask scheduler did not start: {self.log(0)}")

    def worker(self, wait: bool = True) -> subprocess.Popen:
        proc = self._start("dask_worker", self.address, "--no-nanny", "--nthreads", "1", "--no-dashboard",
                           "--host", "127.0.0.1")
        if wait:
            from distributed import Client

            with Client(self.address, timeout=30) as c:
                c.wait_for_workers(sum(p.poll() is None for p in self.procs) - 1, timeout=60)
        return proc

    def log(self, i: int) -> str:
        with open(os.path.join(self.folder, f"dask-{i}.log"), "rb") as f:
            return f.read().decode(errors="replace")[-2000:]

    @staticmethod
    def kill(proc: subprocess.Popen) -> None:
        if proc.poll() is None:
            os.kill(proc.pid, signal.SIGKILL)
        proc.wait()

    def stop(self) -> None:
        for p in self.procs:
            self.kill(p)


class Silent:
    """A TCP server on 127.0.0.1 that accepts connections and never says a word."""

    def __init__(self):
        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(16)
        self.address = f"tcp://127.0.0.1:{self.sock.getsockname()[1]}"
        self.held, self.stopped = [], False
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self):
        while not self.stopped:
            try:
                conn, _ = self.sock.accept()
            except OSError:
                return
            self.held.append(conn)

    def stop(self):
        self.stopped = True
        for c in self.held:
            c.close()
        self.sock.close()


class _Page(BaseHTTPRequestHandler):
    def do_GET(self):  # noqa: N802
        self.send_response(200)
        self.end_headers()
        self.wfile.write(b"<html>not a scheduler</html>")

    def log_message(self, *args):
        pass


class Http:
    """A small HTTP server on 127.0.0.1."""

    def __init__(self):
        self.server = ThreadingHTTPServer(("127.0.0.1", 0), _Page)
        self.address = f"tcp://127.0.0.1:{self.server.server_address[1]}"
        threading.Thread(target=self.server.serve_forever, daemon=True).start()

    def stop(self):
        self.server.shutdown()
        self.server.server_close()
