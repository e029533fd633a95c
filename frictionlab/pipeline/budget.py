"""A fit's time budget, enforced from outside the law's code (``inference.fitting.guard``).

``fit`` keeps its own budget with an alarm that raises in the fitting process; a law plugin's bare
``except:`` can swallow that. So a fit of a third-party law with a budget runs in a forked child
process ended once the budget and a grace of ``guard.grace(timeout)`` seconds have passed: the fit is then
'failed' with the reason, and the next fit gets a fresh process. Built-in laws run here.
"""
from __future__ import annotations

import time

from ..inference.fitting.fit import FitResult, fit
from ..inference.fitting.guard import within_budget
from ..physics.registry import get_law


def fit_within_budget(law, datasets, *, timeout: float | None = None, **options) -> FitResult:
    """``fit(law, datasets, timeout=timeout, **options)``, in a child process ended past the budget for
    a third-party law with a budget (see the module docstring)."""
    started = time.perf_counter()

    def over(reason: str) -> FitResult:
        items = datasets if isinstance(datasets, (list, tuple)) else [datasets]
        names = tuple(getattr(d, "name", str(d)) for d in items)
        return FitResult(law=get_law(law).name, solver=options.get("solver", "auto"), datasets=names,
                         status="failed", wall_time=time.perf_counter() - started, reason=reason)

    return within_budget(_fit, [law], timeout, law, datasets, timeout, options, over=over)


def _fit(law, datasets, timeout, options):
    return fit(law, datasets, timeout=timeout, **options)
