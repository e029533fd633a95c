"""Progress of one fit, counted in model evaluations: the start scan, each Levenberg-Marquardt start
and the error analysis. A start's count is estimated (LM_EVALS per free parameter) and grows by half
when a start needs more, so the ETA is an estimate that corrects itself.

``FitProgress(progress, what)`` wraps a ``progress(done, total, label)`` callable (core.progress.Progress);
the fit calls ``stage`` when a stage begins and ``tick`` after each model evaluation. Calls to
``progress`` are at most every ``EVERY`` seconds (plus each new stage), so counting costs nothing next
to an evaluation.
"""
from __future__ import annotations

import time

#: seconds between two progress calls within one stage
EVERY = 0.25
#: estimated Levenberg-Marquardt evaluations of one start, per free parameter plus one
LM_EVALS = 30


class FitProgress:
    def __init__(self, progress, what: str, total: int):
        self.progress, self.what, self.total = progress, what, max(1, int(total))
        self.done, self.stage_end, self.label, self.count, self.size, self._last = 0, 0, "", 0, 0, -1e9

    def stage(self, label: str, size: int, total: int | None = None):
        """A stage of at most ``size`` evaluations begins (``total``: a new overall total); the count
        jumps to the end of the previous stage."""
        self.done = max(self.done, self.stage_end)
        if total is not None:
            self.total = max(int(total), self.done + size)
        self.stage_end, self.label, self.count, self.size = self.done + size, label, 0, size
        self._call(force=True)

    def tick(self):
        """One model evaluation done."""
        self.count += 1
        if self.done + 1 >= self.stage_end:  # longer than estimated: extend the stage and the total by half
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
