"""frictionlab's own signal handlers kept through code it does not trust (a law plugin's import or call).

A plugin may set SIGINT, SIGTERM or SIGHUP to SIG_IGN or to its own handler, at import or in a call;
``kept_signals()`` puts back, when the block ends (normally or not), the handlers that were in place
when it began, so that ^C, SIGTERM and SIGHUP still end the run cleanly (exit status, clean-up).
"""
from __future__ import annotations

import signal
import threading
from contextlib import contextmanager

#: The signals a run ends on, each with its own handler (cli._signals_end_cleanly, Python's ^C).
ENDING = tuple(getattr(signal, n) for n in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, n))


@contextmanager
def kept_signals():
    """The handlers of ``ENDING`` as they are now, restored after the block (main thread only: signal
    handlers can be set only there; elsewhere a no-op)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    saved = {s: signal.getsignal(s) for s in ENDING}
    try:
        yield
    finally:
        for s, handler in saved.items():
            if handler is not None and signal.getsignal(s) is not handler:
                signal.signal(s, handler)
