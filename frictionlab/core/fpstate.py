"""frictionlab's own floating-point error state, whatever a caller or a plugin has set with ``np.seterr``.

A notebook or a law plugin may set ``np.seterr(all="raise")``; frictionlab's laws and solvers are written for
numpy's default state (an underflow in ``exp`` is a zero, an overflow a warning and an infinity that the code
checks), so its entry points (the command line, the registry's loading of laws, ``fit``, ``simulate``,
``compare``, ``write_report``) run under ``own_errstate()``, and the caller's state is back afterwards.
"""
from __future__ import annotations

import functools
from contextlib import contextmanager

#: numpy's default error state: what frictionlab's numerical code is written for.
NUMPY_ERRORS = {"divide": "warn", "over": "warn", "under": "ignore", "invalid": "warn"}


@contextmanager
def own_errstate():
    """The block run under ``NUMPY_ERRORS``; the error state before it restored afterwards."""
    import numpy as np

    with np.errstate(**NUMPY_ERRORS):
        yield


def with_own_errstate(fn):
    """``fn`` run under ``own_errstate()`` (a decorator for entry points)."""

    @functools.wraps(fn)
    def run(*args, **kwargs):
        with own_errstate():
            return fn(*args, **kwargs)

    return run
