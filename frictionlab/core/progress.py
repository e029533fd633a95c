"""Progress for long runs: a tqdm bar on a terminal, plain timestamped lines when not, nothing when quiet.

``Progress(desc)`` is a callable ``progress(done, total, label)`` (the signature ``compare``,
``write_report`` and the bootstrap take). On a terminal it draws a tqdm bar with the count, the
rate and the ETA. On anything else (a log file, a pipe) it writes lines such as
``2026-11-23 01:02:03 compare: 12/40 (30%) wear [exact] on impact-golf-v28; ETA 0:01:10`` to
stderr, at most one per ``every`` seconds plus the first and the last, and a "still working" line
when a single step takes longer than ``heartbeat`` seconds, so a redirected run is never silent
and a log stays short. ``quiet=True`` silences it.
"""
from __future__ import annotations

import datetime as _dt
import sys
import threading
import time


def _clock(seconds: float) -> str:
    seconds = max(0, int(round(seconds)))
    return f"{seconds // 3600}:{seconds // 60 % 60:02d}:{seconds % 60:02d}"


class Progress:
    """progress(done, total, label); use as a context manager or call close() at the end."""

    def __init__(self, desc: str, stream=None, quiet: bool = False, every: float = 5.0, tty: bool | None = None,
                 heartbeat: float = 30.0):
        self.desc, self.stream, self.quiet, self.every = desc, stream or sys.stderr, quiet, every
        self.tty = (hasattr(self.stream, "isatty") and self.stream.isatty()) if tty is None else tty
        self.start = time.monotonic()
        self.last_line = -1e9
        self.bar = None
        self.done, self.total = 0, 0
        self.heartbeat = heartbeat
        self._stop = threading.Event()
        self._lock = threading.Lock()
        self._beat = None

    def __call__(self, done: int, total: int, label: str = "") -> None:
        if self.quiet:
            return
        if self.tty:
            self._draw(done, total, label)
        else:
            now = time.monotonic()
            if done in (1, total) or done < self.done or now - self.last_line >= self.every:
                self._write(self.line(done, total, label, now), now)
            if self._beat is None and self.heartbeat:
                self._beat = threading.Thread(target=self._beats, daemon=True)
                self._beat.start()
        self.done, self.total = done, total

    def _write(self, text: str, now: float) -> None:
        with self._lock:
            self.last_line = now
            self.stream.write(text + "\n")
            self.stream.flush()

    def _beats(self) -> None:
        """A 'still working' line whenever nothing was written for ``heartbeat`` seconds."""
        while not self._stop.wait(min(self.heartbeat, 5.0)):
            now = time.monotonic()
            if now - self.last_line >= self.heartbeat and self.done < self.total:
                stamp = _dt.datetime.now().strftime("%Y-%m-%d %H:%M:%S")
                self._write(f"{stamp} {self.desc}: {self.done}/{self.total} done, still working "
                            f"({_clock(now - self.start)} so far)", now)

    def line(self, done: int, total: int, label: str, now: float | None = None) -> str:
        """The plain progress line: time stamp, count, share, label and ETA."""
        elapsed = (now if now is not None else time.monotonic()) - self.start
        share = done / total if total else 1.0
        eta = f"ETA {_clock(elapsed * (1 - share) / share)}" if 0 < share < 1 else f"took {_clock(elapsed)}"
        stamp = _dt.datetime.now().strftime("%Y-%m-%d %H:%M:%S")
        return f"{stamp} {self.desc}: {done}/{total} ({100 * share:.0f}%) {label}; {eta}"

    def _draw(self, done: int, total: int, label: str) -> None:
        if self.bar is None:
            from tqdm import tqdm

            # the bar redraws with carriage returns, which the inert stream (core.terminal) would drop: it
            # draws on the stream beneath; its text is names and numbers (core.names), nothing to neutralise
            self.bar = tqdm(total=total, desc=self.desc, file=getattr(self.stream, "unfiltered", self.stream), dynamic_ncols=True, leave=True,
                            bar_format="{desc}: {bar} {n_fmt}/{total_fmt} [{elapsed}<{remaining}] {postfix}")
        if self.bar.total != total:
            self.bar.total = total
        self.bar.n = done
        self.bar.set_postfix_str(label[:60], refresh=False)
        self.bar.refresh()

    def close(self) -> None:
        self._stop.set()
        if self.bar is not None:
            self.bar.close()
            self.bar = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
