"""Progress for long runs: a tqdm bar on a terminal, plain timestamped lines when not, nothing when quiet.

``Progress(desc)`` is a callable ``progress(done, total, label)`` (the signature ``compare``,
``write_report`` and the bootstrap take). On a terminal it draws a tqdm bar with the count, the
rate and the ETA. On anything else (a log file, a pipe) it writes lines such as
``2026-11-23 01:02:03 compare: fit 12/40 (30%) wear [exact] on impact-golf-v28; ETA 0:01:10`` to
stderr, at most one per ``every`` seconds plus the first and the last of a count, never a carriage
return. A heartbeat (a daemon thread) keeps a long step from being silent: every ``heartbeat``
seconds without a line it writes a "still working" line naming the count, the last label and how
long nothing has finished (on a terminal it redraws the bar, whose clock then moves). ``delay``:
nothing at all from a run shorter than that. ``quiet=True`` silences it.

``progress.stage(name)`` gives a child with its own count, clock and ETA (a pipeline stage: its lines
read ``compare: fit 3/16 ...``); the parent's heartbeat watches it until it is closed. ``Running``
tells which tasks of a process pool run now and for how long, from the parent's side alone.
"""
from __future__ import annotations

import datetime as _dt
import sys
import threading
import time
from collections import deque

#: Moves of the count the ETA's rate is measured over: the last RATE_STEPS, their seconds over their counts (the time
#: to the first move, which pays for imports and compilation, never counts; see ``Progress.eta``).
RATE_STEPS = 64
#: Moves after the first the ETA waits for: a median of three outvotes one move that compiled.
FIRST_RATES = 3
#: A move slower per count than OUTLIER times the median move is left out of the rate (a compilation, a stall).
OUTLIER = 5.0


def _clock(seconds: float) -> str:
    seconds = max(0, int(round(seconds)))
    return f"{seconds // 3600}:{seconds // 60 % 60:02d}:{seconds % 60:02d}"


def _stamp() -> str:
    return _dt.datetime.now().strftime("%Y-%m-%d %H:%M:%S")


class Progress:
    """progress(done, total, label); use as a context manager or call close() at the end.

    clock: a function returning seconds (time.monotonic; a test passes a fake one); thread=False: no
    heartbeat thread, the caller calls ``beat()`` (a test)."""

    def __init__(self, desc: str, stream=None, quiet: bool = False, every: float = 5.0, tty: bool | None = None,
                 heartbeat: float = 5.0, delay: float = 0.0, clock=time.monotonic, *, thread: bool = True,
                 _parent=None, _stage: str = ""):
        self.desc, self.stream, self.quiet, self.every = desc, stream or sys.stderr, quiet, every
        self.tty = (hasattr(self.stream, "isatty") and self.stream.isatty()) if tty is None else tty
        self.clock, self.heartbeat, self.delay = clock, heartbeat, delay  # delay: seconds of silence
        self.start = self.since = clock()  # since: when the count last moved
        self.last_line = -1e18
        self.bar = None
        self.done, self.total, self.label, self.name = 0, 0, "", _stage
        self.marks: deque = deque(maxlen=RATE_STEPS + 1)  # (time, count) where the count moved
        self.parent = _parent
        self._lock = _parent._lock if _parent is not None else threading.Lock()
        self._stop = threading.Event()
        self._children: list[Progress] = []
        self._beat = None if thread else False

    def __call__(self, done: int, total: int, label: str = "") -> None:
        if self.quiet:
            return
        now = self.clock()
        if done != self.done:
            self.since = now
        first, moved, back = self.last_line < -1e17, done != self.done, done < self.done
        if back:
            self.marks.clear()
        if moved or back:
            self.marks.append((now, done))
        self.done, self.total, self.label = done, total, label
        self._watch()
        if self.delay and now - self.start < self.delay:
            return
        if self.tty:
            self._draw(done, total, label)
        elif first or back or (moved and done in (1, total)) or now - self.last_line >= self.every:
            self._write(self.line(done, total, label, now), now)

    def restart_rate(self) -> None:
        """Steps of another kind follow (a fit's Levenberg-Marquardt runs after its scan of start points): the rate
        is measured afresh from the next move on, and the ETA waits for FIRST_RATES moves after it."""
        self.marks.clear()

    def stage(self, name: str) -> "Progress":
        """A child counting one stage (its own count, clock, ETA and bar); close it when the stage ends."""
        child = Progress(self.desc, self.stream, self.quiet, self.every, self.tty, self.heartbeat, 0.0, self.clock,
                         thread=False, _parent=self, _stage=name)
        with self._lock:
            self._children.append(child)
        return child

    def _watch(self) -> None:
        """Start the heartbeat thread of the root, once."""
        root = self.parent or self
        if root._beat is None and root.heartbeat and not root.quiet:
            root._beat = threading.Thread(target=root._beats, daemon=True)
            root._beat.start()

    def _write(self, text: str, now: float) -> None:
        with self._lock:
            self.last_line = now
            self.stream.write(text + "\n")
            self.stream.flush()

    def _beats(self) -> None:
        while not self._stop.wait(min(self.heartbeat, 1.0)):
            self.beat()

    def beat(self) -> None:
        """One heartbeat: for every count not finished and without a line for ``heartbeat`` seconds, its
        plain line if it moved since, else a 'still working' line (on a terminal: the bar redrawn)."""
        with self._lock:
            watched = [self] + list(self._children)
        now = self.clock()
        for p in watched:
            if p.done >= p.total or now - p.last_line < p.heartbeat or (p.delay and now - p.start < p.delay):
                continue
            if p.tty:
                if p.bar is not None:
                    p.last_line = now
                    p.bar.refresh()
                continue
            # the count moved since the last line: the plain line with its ETA; else 'still working'
            p._write(p.line(p.done, p.total, p.label, now) if now - p.since < p.heartbeat else p.still(now), now)

    def still(self, now: float) -> str:
        """The 'still working' line: count, how long nothing finished, the last label."""
        return (f"{_stamp()} {self.desc}: {self._name()}{self.done}/{self.total} done, still working "
                f"(nothing finished for {_clock(now - self.since)}, {_clock(now - self.start)} so far)"
                + (f"; last: {self.label}" if self.label else ""))

    def _name(self) -> str:
        return f"{self.name} " if self.name else ""

    def line(self, done: int, total: int, label: str, now: float | None = None) -> str:
        """The plain progress line: time stamp, stage, count, share, label and ETA (``eta``)."""
        now = now if now is not None else self.clock()
        share = done / total if total else 1.0
        left = self.eta(done, total, now) if 0 < share < 1 else None
        eta = (f"ETA {_clock(left)}" if left is not None else "ETA after the first steps" if share < 1 else
               f"took {_clock(now - self.start)}")
        return f"{_stamp()} {self.desc}: {self._name()}{done}/{total} ({100 * share:.0f}%) {label}; {eta}"

    def eta(self, done: int, total: int, now: float) -> float | None:
        """Seconds left: the counts left times the measured rate, the seconds over the counts of the last RATE_STEPS
        moves of the count, less any move slower per count than OUTLIER times their median; None before the count
        has moved FIRST_RATES times after its first move. Not the mean over the whole run: the first step pays for
        imports and compilation, and would make every later step look that slow (a fit whose first evaluation
        compiled for a minute promised hours)."""
        marks = [m for m in self.marks if m[1] <= done]
        steps = [(t1 - t0, d1 - d0) for (t0, d0), (t1, d1) in zip(marks, marks[1:]) if d1 > d0]
        if len(steps) < FIRST_RATES:
            return None
        per = sorted(s / n for s, n in steps)
        typical = per[len(per) // 2]
        kept = [(s, n) for s, n in steps if s <= OUTLIER * typical * n]
        return (total - done) * sum(s for s, _ in kept) / sum(n for _, n in kept)

    def _draw(self, done: int, total: int, label: str) -> None:
        if self.bar is None:
            from tqdm import tqdm

            # the bar redraws with carriage returns, which the inert stream (core.terminal) would drop: it
            # draws on the stream beneath; its text is names and numbers (core.names), nothing to neutralise
            self.bar = tqdm(total=total, desc=f"{self.desc} {self.name}".strip(), dynamic_ncols=True, leave=True,
                            file=getattr(self.stream, "unfiltered", self.stream),
                            bar_format="{desc}: {bar} {n_fmt}/{total_fmt} [{elapsed}<{remaining}] {postfix}")
        if self.bar.total != total:
            self.bar.total = total
        self.bar.n = done
        self.bar.set_postfix_str(label[:60], refresh=False)
        self.bar.refresh()
        self.last_line = self.clock()

    def close(self) -> None:
        if self.parent is not None:
            with self._lock:
                if self in self.parent._children:
                    self.parent._children.remove(self)
        self._stop.set()
        if self.bar is not None:
            self.bar.close()
            self.bar = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class Running:
    """Which tasks submitted in order to a pool of ``workers`` processes run now, and since when.

    A process pool hands tasks out in the order they were submitted, one to each free worker, so task
    i starts when the pool starts (i < workers) or when the (i - workers + 1)-th task finishes: the
    parent knows it without hearing from the workers. ``finished(i)`` when task i ends; ``now(names)``
    the running tasks' names with their seconds."""

    def __init__(self, n: int, workers: int, clock=time.monotonic):
        self.clock, self.workers = clock, max(1, workers)
        self.t0 = clock()
        self.ends: list[float] = []
        self.left = set(range(n))

    def finished(self, i: int) -> None:
        self.left.discard(i)
        self.ends.append(self.clock())

    def now(self, names, shown: int = 3) -> str:
        """'lugre [ode] on X 12 s, dahl [ode] on X 3 s' for the tasks running now (at most ``shown``)."""
        now, started = self.clock(), self.workers + len(self.ends)
        running = sorted(i for i in self.left if i < started)
        parts = [f"{names(i)} {now - (self.t0 if i < self.workers else self.ends[i - self.workers]):.0f} s"
                 for i in running[:shown]]
        more = len(running) - shown
        return ", ".join(parts) + (f" and {more} more" if more > 0 else "")
