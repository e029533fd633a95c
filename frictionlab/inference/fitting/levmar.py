"""lmfit's Levenberg-Marquardt run for the refits, without its per-run bookkeeping.

``leastsq(fun, params, scale_covar, max_nfev, **options)`` is what ``lmfit.Minimizer(...).minimize(
method="leastsq")`` computes for parameters with bounds and no expressions: the same bound
transformation (MINUIT's, with numpy's sin/arcsin/sqrt), the same scipy ``leastsq`` call, the same
statistics and error analysis (covariance through the transformation's gradient, scaled by the
reduced chi-square when asked), so the same numbers, bit for bit (``tests/test_fit_path.py``). It
skips what costs ~0.5 ms a run: copying the Parameters (each copy builds an expression interpreter),
uncertainty objects, per-call bookkeeping; worth it for the thousands of warm-started refits of the
equivalence test and the bootstrap (``fit(checks=False)``). Where lmfit would take another path (a
residual that is not finite, the evaluation budget reached) it returns None and the caller runs lmfit.
"""
from __future__ import annotations

import math

import numpy as np
import scipy.optimize
from numpy import arcsin, cos, inf, sin, sqrt

TINY = 1.0e-15  # lmfit.lineshapes.tiny: an internal start closer to 0 than this is 0


def lmfit_bound(b: float, slot) -> float:
    """The bound b handed to lmfit for a parameter slot (``fitmodel._Slot``: its scale): infinite where it is far
    outside the parameter's scale (the law still checks it)."""
    return b if abs(b) <= 1e4 * slot.scale else math.copysign(inf, b)


class Param:
    """What a fit reads of a fitted lmfit Parameter."""

    __slots__ = ("name", "value", "min", "max", "vary", "stderr", "correl")

    def __init__(self, name, value, lo, hi, vary):
        self.name, self.min, self.max, self.vary = name, lo, hi, vary
        self.value = hi if value > hi else (lo if value < lo else value)  # lmfit clips a value into its bounds
        self.stderr = self.correl = None

    def set(self, value) -> None:
        """lmfit's ``Parameter.set(value=...)``: the value clipped into the bounds."""
        self.value = self.max if value > self.max else (self.min if value < self.min else value)

    def internal(self) -> float:
        """lmfit's ``Parameter.setup_bounds``: the optimizer's value for this value."""
        lo, hi, v = self.min, self.max, self.value
        if lo == -inf and hi == inf:
            x = v
        elif hi == inf:
            x = sqrt((v - lo + 1.0)**2 - 1)
        elif lo == -inf:
            x = sqrt((hi - v + 1.0)**2 - 1)
        else:
            x = arcsin(2*(v - lo)/(hi - lo) - 1)
        return 0.0 if abs(x) < TINY else float(x)

    def external(self, val) -> float:
        """lmfit's ``from_internal``."""
        lo, hi = self.min, self.max
        if lo == -inf and hi == inf:
            return float(val)
        if hi == inf:
            return float(lo - 1.0 + sqrt(val*val + 1))
        if lo == -inf:
            return float(hi + 1 - sqrt(val*val + 1))
        return float(lo + (sin(val) + 1) * (hi - lo) / 2.0)

    def gradient(self, val):
        """lmfit's ``scale_gradient``: d external / d internal at internal value val."""
        lo, hi = self.min, self.max
        if lo == -inf and hi == inf:
            return 1.0
        if hi == inf:
            return val / sqrt(val*val + 1)
        if lo == -inf:
            return -val / sqrt(val*val + 1)
        return cos(val) * (hi - lo) / 2.0


def lmfit_parameters(params):
    """lmfit Parameters for a mapping name -> Param (lmfit Parameters are returned as they are)."""
    import lmfit

    if isinstance(params, lmfit.Parameters):
        return params
    out = lmfit.Parameters()
    for k, p in params.items():
        out.add(k, value=p.value, vary=p.vary, min=p.min, max=p.max)
    return out


class Result:
    """What a fit reads of lmfit's MinimizerResult: params (name -> Param), success, message, chisqr."""

    def __init__(self, params, success, message, chisqr):
        self.params, self.success, self.message, self.chisqr = params, success, message, chisqr


class _Other(Exception):
    """lmfit would take a path this module does not reproduce."""


MESSAGES = {0: "Invalid Input Parameters. I.e. more variables than data points given, tolerance < 0.0, or "
               "no data provided.",
            4: "One or more variable did not affect the fit."}


def leastsq(fun, params, scale_covar: bool, max_nfev: int, **options) -> Result | None:
    """Minimize sum(fun(values)**2) over the varying parameters of ``params`` (lmfit Parameters, or a
    mapping name -> Param: fit() builds those for a refit) as lmfit's ``leastsq`` method does; fun takes a dict name -> value. options:
    scipy leastsq keywords (ftol, xtol, epsfcn). None where lmfit would go another way."""
    pars = {k: Param(k, float(p.value), -inf if p.min is None else p.min, inf if p.max is None else p.max, p.vary)
            for k, p in params.items()}
    free = [p for p in pars.values() if p.vary]
    values = {k: p.value for k, p in pars.items()}
    calls = [0]

    def residual(x):
        calls[0] += 1
        if calls[0] > max_nfev + 2:  # lmfit aborts the run here (its count starts at -2)
            raise _Other()
        for p, v in zip(free, x if x.shape != () else x.reshape((1,))):
            p.set(p.external(v))
            values[p.name] = p.value
        r = np.asarray(fun(dict(values)), dtype=np.float64).ravel()
        if not np.isfinite(r).all():  # lmfit raises its own error for this
            raise _Other()
        return r

    kws = dict(Dfun=None, full_output=1, col_deriv=0, ftol=1.5e-8, xtol=1.5e-8, gtol=0.0, maxfev=2 * max_nfev,
               epsfcn=1.e-10, factor=100, diag=None)
    kws.update(options)
    with np.errstate(all="ignore"):
        try:
            best, cov, _, _, ier = scipy.optimize.leastsq(residual, [p.internal() for p in free], **kws)
            r = residual(best)
        except _Other:
            return None
        chisqr = (r**2).sum()
        redchi = chisqr / max(1, len(r) - len(free))
        chisqr = max(chisqr, 1.e-250 * len(r))
        message = "Fit succeeded." if ier in (1, 2, 3) else MESSAGES.get(ier, "Tolerance seems to be too small.")
        if ier == 5:
            return None
        if cov is None:
            message += " Could not estimate error-bars."
        else:
            g = np.atleast_2d([p.gradient(best[i]) for i, p in enumerate(free)])
            covar = cov * np.dot(g.T, g)
            if scale_covar:
                covar *= redchi
            for p in pars.values():
                p.stderr, p.correl = 0, None
            for i, p in enumerate(free):
                p.stderr = float(np.sqrt(covar[i, i]))
                p.correl = {}
                for j, q in enumerate(free):
                    if j != i:
                        p.correl[q.name] = float(covar[i, j] / (p.stderr * np.sqrt(covar[j, j])))
    return Result(pars, ier in (1, 2, 3, 4), message, chisqr)
