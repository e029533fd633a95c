"""The time budget of a fit in this process: an alarm that raises FitTimeout in the main thread, never inside an
import or numba's compiler. Units: seconds."""
from __future__ import annotations

import signal
import threading
from contextlib import contextmanager


class FitTimeout(BaseException):
    """A fit ran past its time budget (a BaseException, so that no handler of a law's errors keeps it)."""


#: Seconds after which an alarm that rang inside an import or numba's compiler rings again.
ALARM_RETRY = 0.02


def importing_or_compiling(frame) -> bool:
    """Whether ``frame`` runs inside Python's import system or numba (a module being imported, a kernel being
    compiled or loaded from numba's cache): an exception raised there would leave the process's modules or
    numba's registries half set up for every later call, not just this fit."""
    while frame is not None:
        name = frame.f_globals.get("__name__", "")
        if name.startswith(("importlib", "numba.", "llvmlite.")):
            return True
        frame = frame.f_back
    return False


@contextmanager
def alarm(seconds: float | None):
    """Raise FitTimeout in the main thread after ``seconds`` (no-op elsewhere, or if an alarm is set); where the
    alarm rings inside an import or numba (``importing_or_compiling``), once that is done."""
    if (seconds is None or not hasattr(signal, "setitimer") or threading.current_thread() is not threading.main_thread()
            or signal.getitimer(signal.ITIMER_REAL)[0] > 0):
        yield
        return

    def ring(signum, frame):
        if importing_or_compiling(frame):  # never leave a module half imported or numba half set up
            signal.setitimer(signal.ITIMER_REAL, ALARM_RETRY)
            return
        raise FitTimeout()

    old = signal.signal(signal.SIGALRM, ring)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
