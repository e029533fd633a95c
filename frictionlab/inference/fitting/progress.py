"""Progress of one fit, counted in model evaluations: the start scan, each Levenberg-Marquardt start
and the error analysis. The first start's count is estimated on the low side (LM_EVALS per free parameter
plus one), later ones at the median of the starts done; a stage that needs more grows by half, so the ETA
(``core.progress``: the counts left at the measured rate) corrects itself upwards rather than promising
more time than the fit takes.

``FitProgress(progress, what)`` wraps a ``progress(done, total, label)`` callable (core.progress.Progress);
the fit calls ``stage`` when a stage begins and ``tick`` after each model evaluation. Calls to
``progress`` are at most every ``EVERY`` seconds (plus each new stage), so counting costs nothing next
to an evaluation.
"""
from __future__ import annotations

import statistics
import time

#: seconds between two progress calls within one stage
EVERY = 0.25
#: estimated Levenberg-Marquardt evaluations of one start, per free parameter plus one (about ten iterations, each
#: a difference-quotient Jacobian and a step; a start that needs more grows its stage)
LM_EVALS = 10


class FitProgress:
    def __init__(self, progress, what: str, total: int):
        self.progress, self.what, self.total = progress, what, max(1, int(total))
        self.done, self.stage_end, self.label, self.count, self.size, self._last = 0, 0, "", 0, 0, -1e9
        self.starts: list[int] = []  # evaluations of each Levenberg-Marquardt start done

    def stage(self, label: str, size: int, total: int | None = None, other_kind: bool = False):
        """A stage of about ``size`` evaluations begins; ``total``: a new overall total counted from the
        evaluations done, else the count jumps to the estimated end of the previous stage. ``other_kind``: its
        evaluations cost what those before did not (a scan's against Levenberg-Marquardt's): the rate is measured
        afresh (``restart_rate`` of the progress, where it has one)."""
        restart = getattr(self.progress, "restart_rate", None)
        if other_kind and restart is not None:
            restart()
        if total is None:
            self.done = max(self.done, self.stage_end)
        else:
            self.total = max(int(total), self.done + size)
        self.stage_end, self.label, self.count, self.size = self.done + size, label, 0, size
        self._call(force=True)

    def start(self, i: int, n: int, guess: int, tail: int):
        """Levenberg-Marquardt start ``i + 1`` of ``n`` begins; ``guess``: evaluations of a start before one
        is done; ``tail``: evaluations after the last start (the error analysis)."""
        if i > 0:
            self.starts.append(self.count)
        size = max(1, round(statistics.median(self.starts))) if self.starts else guess
        self.stage(f"Levenberg-Marquardt start {i + 1} of {n}", size, total=self.done + (n - i) * size + tail,
                   other_kind=i == 0)

    def tick(self):
        """One model evaluation done."""
        self.count += 1
        if self.done >= self.stage_end:  # longer than estimated: extend the stage and the total by half
            grow = max(1, self.size // 2)
            self.stage_end, self.size, self.total = self.stage_end + grow, self.size + grow, self.total + grow
        self.done += 1
        self._call()

    def _call(self, force: bool = False):
        now = time.monotonic()
        if force or now - self._last >= EVERY:
            self._last = now
            self.progress(min(self.done, self.total), self.total,
                          f"{self.what}: {self.label}, {self.count} evaluations")

    def finish(self, label: str = "done"):
        self.done = self.total
        self.progress(self.total, self.total, f"{self.what}: {label}")
