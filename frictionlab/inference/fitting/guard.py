"""Calls into a third-party law's code, their time budget enforced from outside that code.

A built-in law is trusted: its code cooperates with the in-process alarm of ``fitting.fit`` (a
fit past its budget is 'failed'), so it runs here, with no fork and no pickling. A third-party
law (its class defined outside frictionlab: a plugin, a --load file, a notebook) may swallow that
alarm in a bare ``except:``. So every call a stage makes into such a law's code with a time budget
(a fit, a batch of refits, the equivalence test of a pair, a transfer candidate, a bootstrap chunk,
a tolerance refit) runs in a forked child process (``core.workers.bounded``) that is ended once
``timeout + grace(timeout)`` seconds pass without a new fit starting (``fitting.fit`` beats at its
start): a batch of refits in one child keeps the budget of each refit, and the next call gets a
fresh child. The caller turns a child ended that way into its own 'failed' value (``over``). A
call made here (no budget) keeps the process's SIGINT/SIGTERM/SIGHUP handlers, whatever the law
sets.
"""
from __future__ import annotations

from collections.abc import Callable, Iterable

from ...core.signals import kept_signals
from ...core.workers import OverBudget, bounded
from ...physics.registry import is_third_party


def grace(timeout: float) -> float:
    """Seconds past the budget before the call's process is ended (the alarm inside normally wins)."""
    return 1.0 + 0.1 * timeout


def over_reason(timeout: float, exc: Exception | str) -> str:
    """The reason a call ended from outside gives (one line)."""
    return (f"exceeded its time budget of {timeout:g} s (--fit-timeout): the law's code did not stop, "
            f"so its process was ended ({exc})")


def within_budget(fn: Callable, laws: Iterable, timeout: float | None, *args, over: Callable[[str], object]):
    """``fn(*args)``: here for trusted ``laws`` or no budget; else in a child ended past the budget,
    and then ``over(reason)`` (see the module docstring)."""
    if not any(is_third_party(law) for law in laws):
        return fn(*args)
    if timeout is None:
        with kept_signals():
            return fn(*args)
    try:
        return bounded(fn, timeout + grace(timeout), *args)
    except OverBudget as exc:
        return over(over_reason(timeout, exc))
