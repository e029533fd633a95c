"""A warm-started refit through scipy's public least squares, for the replicate refits.

``leastsq(fun, params, scale_covar, max_nfev, **options)`` minimizes sum(fun(values)**2) over the varying
parameters from their values (the main fit's best values: a warm start) by Levenberg-Marquardt
(``scipy.optimize.least_squares(method="lm")``, MINPACK's lmdif, forward differences of relative step
sqrt(epsfcn)) in MINUIT's bounded coordinates (F. James, MINUIT reference manual, CERN D506, "parameter limits":
arcsin for two bounds, sqrt for one; lmfit bounds its parameters the same way, so a refit walks as lmfit's would).
It returns what a fit reads of lmfit's result: the parameters (values; error bars and correlations from the
Jacobian at the end through the coordinates' gradient, scaled by the reduced chi-square when asked), success, a
message and chi-square. It skips what costs about 0.5 ms a run in lmfit (copying the Parameters, uncertainty
objects), which the thousands of refits of the equivalence test and the bootstrap (``fit(checks=False)``) would
pay. Where the residual is not finite or the evaluation budget runs out it returns None, and the caller runs
lmfit's own Levenberg-Marquardt.
"""
from __future__ import annotations

import math

import numpy as np
from numpy import inf


def lmfit_bound(b: float, slot) -> float:
    """The bound b handed to the optimizer for a parameter slot (``fitmodel._Slot``: its scale): infinite where it
    is far outside the parameter's scale (the law still checks it)."""
    return b if abs(b) <= 1e4 * slot.scale else math.copysign(inf, b)


class Param:
    """What a fit reads of a fitted parameter (as of an lmfit Parameter): name, value, bounds, vary, stderr,
    correl."""

    __slots__ = ("correl", "max", "min", "name", "stderr", "value", "vary")

    def __init__(self, name, value, lo, hi, vary):
        self.name, self.min, self.max, self.vary = name, lo, hi, vary
        self.value = min(max(value, lo), hi)  # a value clipped into its bounds
        self.stderr = self.correl = None

    def set(self, value) -> None:
        """The value clipped into the bounds (as lmfit's ``Parameter.set(value=...)``)."""
        self.value = min(max(value, self.min), self.max)


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


def internal(x: float, lo: float, hi: float) -> float:
    """MINUIT's internal coordinate of a value x within [lo, hi] (either may be infinite)."""
    if lo == -inf and hi == inf:
        return x
    if hi == inf:
        return math.sqrt((x - lo + 1.0) ** 2 - 1.0)
    if lo == -inf:
        return math.sqrt((hi - x + 1.0) ** 2 - 1.0)
    return math.asin(max(-1.0, min(1.0, 2.0 * (x - lo) / (hi - lo) - 1.0)))


def external(u: float, lo: float, hi: float) -> float:
    """The value of MINUIT's internal coordinate u (the inverse of ``internal``)."""
    if lo == -inf and hi == inf:
        return u
    if hi == inf:
        return lo - 1.0 + math.sqrt(u * u + 1.0)
    if lo == -inf:
        return hi + 1.0 - math.sqrt(u * u + 1.0)
    return lo + (math.sin(u) + 1.0) * (hi - lo) / 2.0


def gradient(u: float, lo: float, hi: float) -> float:
    """d external / d internal at u."""
    if lo == -inf and hi == inf:
        return 1.0
    if hi == inf:
        return u / math.sqrt(u * u + 1.0)
    if lo == -inf:
        return -u / math.sqrt(u * u + 1.0)
    return math.cos(u) * (hi - lo) / 2.0


def leastsq(fun, params, scale_covar: bool, max_nfev: int, ftol: float = 1.5e-8, xtol: float = 1.5e-8,
            epsfcn: float = 1e-10) -> Result | None:
    """Minimize sum(fun(values)**2) over the varying parameters of ``params`` (lmfit Parameters, or a mapping
    name -> Param) from their values; fun takes a dict name -> value. None where the residual is not finite or
    ``max_nfev`` evaluations do not reach convergence (the caller then runs lmfit)."""
    from scipy.optimize import least_squares

    pars = {k: Param(k, float(p.value), -inf if p.min is None else p.min, inf if p.max is None else p.max, p.vary)
            for k, p in params.items()}
    free = [p for p in pars.values() if p.vary]
    values = {k: p.value for k, p in pars.items()}
    finite = [True]

    def residual(u):
        for p, v in zip(free, u):
            values[p.name] = min(max(external(v, p.min, p.max), p.min), p.max)
        r = np.asarray(fun(dict(values)), dtype=np.float64).ravel()
        if not np.isfinite(r).all():
            finite[0] = False
            r = np.where(np.isfinite(r), r, 1e150)  # MINPACK goes on; the refit is declined below
        return r

    u0 = np.array([internal(p.value, p.min, p.max) for p in free])
    with np.errstate(all="ignore"):
        try:
            run = least_squares(residual, u0, method="lm", diff_step=math.sqrt(epsfcn), ftol=ftol, xtol=xtol,
                                gtol=np.finfo(float).eps, max_nfev=max_nfev)
        except ValueError:  # fewer points than free parameters
            return None
        r = residual(run.x)
        if run.status <= 0 or not finite[0]:
            return None
        for p, v in zip(free, run.x):
            p.set(external(float(v), p.min, p.max))
        chisqr = float(r @ r)
        message = "Fit succeeded."
        g = np.array([gradient(float(v), p.min, p.max) for p, v in zip(free, run.x)])
        _errors(pars, free, run.jac / g if len(free) else run.jac,
                chisqr / max(1, len(r) - len(free)) if scale_covar else 1.0)
        if free and free[0].stderr is None:
            message += " Could not estimate error-bars."
    return Result(pars, True, message, max(chisqr, 1.e-250 * len(r)))
def _errors(pars: dict, free: list, jac, scale: float) -> None:
    """Error bars and correlations of the free parameters from the Jacobian at the end: covariance (J^T J)^-1,
    times ``scale`` (the reduced chi-square, or 1 where the noise is known); none where J^T J is singular."""
    for p in pars.values():
        p.stderr, p.correl = 0, None
    jtj = jac.T @ jac
    if not len(free) or not np.all(np.isfinite(jtj)) or np.linalg.matrix_rank(jtj) < len(free):
        for p in free:
            p.stderr = None
        return
    cov = np.linalg.inv(jtj) * scale
    d = np.sqrt(np.abs(np.diag(cov)))
    for i, p in enumerate(free):
        p.stderr = float(d[i])
        p.correl = {q.name: float(cov[i, j] / (d[i] * d[j])) for j, q in enumerate(free) if j != i}
