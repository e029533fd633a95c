"""A fit's time budget, enforced from outside the law's code.

``fit`` keeps its own budget with an alarm that raises in the fitting process; a law plugin's bare
``except:`` can swallow that. So a fit of a third-party law (one not defined in frictionlab) runs,
when it has a budget, in a forked child process (``core.workers.bounded``) that is ended once the
budget and a grace of ``grace(timeout)`` seconds have passed: the fit is then 'failed' with the
reason, and the next fit gets a fresh process. Built-in laws, whose code cooperates with the alarm,
run in this process (a fork costs some 40 ms per fit).
"""
from __future__ import annotations

import time

from ..core.workers import OverBudget, bounded
from ..inference.fitting import FitResult, fit
from ..physics.registry import get_law


def grace(timeout: float) -> float:
    """Seconds past the budget before the fit's process is ended (the alarm inside normally wins)."""
    return 1.0 + 0.1 * timeout


def is_third_party(law) -> bool:
    """True for a law whose class is defined outside frictionlab (a plugin, a --load file, a notebook)."""
    return not type(get_law(law)).__module__.startswith("frictionlab.")


def fit_within_budget(law, datasets, *, timeout: float | None = None, **options) -> FitResult:
    """``fit(law, datasets, timeout=timeout, **options)``, in a child process ended past the budget for
    a third-party law with a budget (see the module docstring)."""
    if timeout is None or not is_third_party(law):
        return fit(law, datasets, timeout=timeout, **options)
    started = time.perf_counter()
    try:
        return bounded(_fit, timeout + grace(timeout), law, datasets, timeout, options)
    except OverBudget as exc:
        items = datasets if isinstance(datasets, (list, tuple)) else [datasets]
        names = tuple(getattr(d, "name", str(d)) for d in items)
        return FitResult(law=get_law(law).name, solver=options.get("solver", "auto"), datasets=names,
                         status="failed", wall_time=time.perf_counter() - started,
                         reason=f"exceeded its time budget of {timeout:g} s (--fit-timeout): the law's code did not "
                                f"stop, so its process was ended ({exc})")


def _fit(law, datasets, timeout, options):
    return fit(law, datasets, timeout=timeout, **options)
