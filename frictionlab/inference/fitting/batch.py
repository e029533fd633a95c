"""Many refits of one law to one dataset's points at once: the equivalence test's and the bootstrap's replicates,
their cross fits, and a fit's start points.

A replicate refit is a small least-squares problem (one or two law parameters, tens of points) solved thousands of
times a comparison; one at a time, each Levenberg-Marquardt step is one closed-form solve through the general phase
driver, and the Python around it is most of the cost. ``refit_many(problem, Y, starts)`` fits every row of Y (r, n)
together instead (``replicates.batch_problem`` poses a refit's problem): one Levenberg-Marquardt run per row, all
rows stepping at once, each step one batched prediction (``predict.predict_array``: the closed forms over a batch of
parameter sets, or the paper's series; stated numbers read off each row's curves; impact outcomes, every row's
impacts in one batch) of every running row's trial point and its forward-difference neighbours.
``best_start(model, starts)`` runs a fit's starts the same way (``fitmodel._search``).

The problem is the one ``fitting.fit`` poses (``replicates.refit``): the same parameter slots, scales and bounds
(``fitmodel._law_slots``), MINUIT's bounded coordinates (F. James, MINUIT reference manual, CERN D506, 1994,
"parameter limits"; lmfit bounds its parameters the same way), lmfit's
forward-difference steps (relative sqrt(1e-10)), the chi-square at the dataset's sigma; Nielsen's damping. Each row
stops where the Gauss-Newton step promises a fall in chi-square below ``FTOL`` of it, or a step is refused whose
promise is below ``RESOLVED`` of it, or its step is below ``XTOL`` of its values, or no damped step lowers it:
a tighter stop than the single refit's (relative tolerance ``fitmodel.FTOL``), so the two agree well within that
tolerance or the batch's minimum lies lower (tests/test_batchfit.py). A row that is not finite, not converged in
``MAX_STEPS`` steps, or whose step the law refuses (a value beyond its bounds) comes back not ok and the caller
refits it alone. None where no batched route serves (a third-party law, a freed scene quantity, an ODE solver,
correlated noise): then every row is refitted alone.
"""
from __future__ import annotations

import math
from collections.abc import Mapping

import attrs
import numpy as np

from ...core.errors import FrictionLabError
from ...physics.registry import is_third_party
from .lsrefit import lmfit_bound
from .predict import predict_array

FTOL = 1e-9  # relative fall in chi-square a Gauss-Newton step may still promise at a row's minimum
MAX_STEPS = 100  # Levenberg-Marquardt steps per row before it is handed back (not ok). Most rows end in 2 to 4; one
# zigzagging across a kink of chi-square (a stick time crossing a sample time) may take 30, which in a batch of its
# own still costs less than a refit alone (an area-rate refit with stick and breakaway: 0.1 s)
STEP = math.sqrt(1e-10)  # lmfit's relative forward-difference step (epsfcn 1e-10)
LAMBDA0, LAMBDA_MAX = 1e-3, 1e12  # Marquardt's damping at the start; past this no step lowers chi-square
XTOL = 1e-10  # relative step of the internal values below which a row stops
TINY = 1.0e-15  # an internal coordinate closer to 0 than this is 0
RESOLVED = 1e-8  # a refused step whose Gauss-Newton promise is below this fraction of chi-square ends the row: the
# promise is then within what forward differences of relative step STEP resolve (a hundredth of fitmodel.FTOL)


@attrs.frozen(eq=False)
class Refits:
    """Rows of ``refit_many``: chisqr (r,), values law parameter -> (r,) [SI] (held ones included), models (r, n)
    [SI], ok (r,) (False: refit that row alone)."""

    chisqr: np.ndarray
    values: dict
    models: np.ndarray
    ok: np.ndarray

    def row(self, i: int) -> dict[str, float]:
        """Row i's law parameter values [SI]."""
        return {k: float(v[i]) for k, v in self.values.items()}


class Problem:
    """One law on one target: its varying parameter slots (``fitmodel._Slot``) in lmfit's bounded coordinates, the
    held ones' values, and the batched prediction."""

    def __init__(self, law, target, solver: str, slots):
        self.law, self.target, self.solver = law, target, solver
        self.held = {s.key: s.value for s in slots if not s.vary}
        self.slots = [s for s in slots if s.vary]
        self.scale = np.array([s.scale for s in self.slots])
        self.lo = np.array([lmfit_bound(s.lower, s) / s.scale for s in self.slots])
        self.hi = np.array([lmfit_bound(s.upper, s) / s.scale for s in self.slots])
        self.start = np.array([s.value / s.scale for s in self.slots])
        self.sigma = np.asarray(target.sigma, dtype=float)
        self.evaluations = 0  # parameter sets predicted so far (each row of each batch)

    def values(self, X: np.ndarray) -> dict[str, np.ndarray]:
        """Law parameters [SI] for scaled external values X (m, k)."""
        m = X.shape[0]
        out = {s.key: X[:, j] * s.scale for j, s in enumerate(self.slots)}
        return out | {k: np.full(m, v) for k, v in self.held.items()}

    def predict(self, X: np.ndarray) -> np.ndarray | None:
        """Predictions (m, n) at scaled values X (m, k); NaN rows where a value is outside its law bounds (lmfit
        passes bounds far beyond a parameter's scale as infinite, so a step may cross them: the law refuses it)."""
        values = self.values(X)
        inside = np.ones(X.shape[0], dtype=bool)
        for spec in self.law.params:
            inside &= (values[spec.name] >= spec.lower) & (values[spec.name] <= spec.upper)
        out = np.full((X.shape[0], self.target.y.size), np.nan)
        if inside.any():
            got = predict_array(self.law, self.target, {k: v[inside] for k, v in values.items()}, self.solver)
            if got is None:
                return None
            out[inside] = got
            self.evaluations += int(inside.sum())
        return out

    def internal(self, X: np.ndarray) -> np.ndarray:
        """MINUIT's internal coordinates per column (arcsin for two bounds, sqrt for one), values clipped into the
        bounds first."""
        lo, hi = self.lo, self.hi
        X = np.clip(X, lo, hi)
        both, upper_only, lower_only = (np.isfinite(lo) & np.isfinite(hi)), np.isinf(lo) & np.isfinite(hi), \
            np.isfinite(lo) & np.isinf(hi)
        with np.errstate(all="ignore"):
            U = np.where(lower_only, np.sqrt((X - lo + 1.0) ** 2 - 1), X)
            U = np.where(upper_only, np.sqrt((hi - X + 1.0) ** 2 - 1), U)
            U = np.where(both, np.arcsin(2 * (X - lo) / np.where(both, hi - lo, 1.0) - 1), U)
        return np.where(np.abs(U) < TINY, 0.0, U)

    def external(self, U: np.ndarray) -> np.ndarray:
        """MINUIT's external values per column (the inverse of ``internal``)."""
        lo, hi = self.lo, self.hi
        both, upper_only, lower_only = (np.isfinite(lo) & np.isfinite(hi)), np.isinf(lo) & np.isfinite(hi), \
            np.isfinite(lo) & np.isinf(hi)
        with np.errstate(all="ignore"):
            X = np.where(lower_only, lo - 1.0 + np.sqrt(U * U + 1), U)
            X = np.where(upper_only, hi + 1 - np.sqrt(U * U + 1), X)
            return np.where(both, lo + (np.sin(U) + 1) * (hi - lo) / 2.0, X)


def served(pr: Problem) -> Problem | None:
    """``pr`` where a batched route may serve it (module docstring), else None; whether ``predict_array`` takes
    its target is known at its first prediction (a refusal there ends the batch: the caller refits alone)."""
    tg = pr.target
    if (is_third_party(pr.law) or pr.solver not in ("exact", "series")
            or getattr(tg.dataset, "noise_correlation", "none") != "none" or not pr.slots
            or tg.y.size < len(pr.slots) + 1):
        return None
    return pr


def best_start(model, starts: list[dict[str, float]]) -> tuple[dict[str, float], float] | None:
    """Of a fit's Levenberg-Marquardt ``starts`` (scaled values of the varying slots by lmfit name), the one whose
    batched run ends lowest, moved to where it ended, and its chi-square; None where no batched route serves
    ``model`` (``fitmodel._Model``: one target, law slots only) or no run converged. A refit takes that end as its
    answer; a fit runs lmfit's Levenberg-Marquardt from there alone, instead of from every start
    (``fitmodel._search``)."""
    if len(model.targets) != 1 or any(s.kind != "law" for s in model.slots):
        return None
    pr = served(Problem(model.law, model.targets[0], model.solvers[0], model.slots))
    if pr is None:
        return None
    X0 = np.array([[st[s.pname] for s in pr.slots] for st in starts])
    try:
        U, chisqr, _, ok = _levenberg_marquardt(pr, np.tile(pr.target.y, (len(starts), 1)), pr.internal(X0))
    except FrictionLabError:
        return None
    finally:
        model.nfev += pr.evaluations  # the fit's count of model evaluations includes the batched ones
    if not ok.any():
        return None
    i = int(np.argmin(np.where(ok, chisqr, np.inf)))
    return {s.pname: float(x) for s, x in zip(pr.slots, pr.external(U[i:i + 1])[0])}, float(chisqr[i])


def refit_many(pr: Problem, Y: np.ndarray, starts: Mapping[str, np.ndarray] | None = None) -> Refits | None:
    """``pr``'s law refitted to every row of Y (r, n) [SI] on its target's points and sigma, each warm-started at
    the slots' values or, per row, at ``starts`` (law parameter -> (r,) [SI]); None where the batch cannot be
    solved (module docstring)."""
    Y = np.atleast_2d(np.asarray(Y, dtype=float))
    r = Y.shape[0]
    X0 = np.tile(pr.start, (r, 1))
    for j, s in enumerate(pr.slots):
        if starts is not None and s.key in starts:
            X0[:, j] = np.asarray(starts[s.key], dtype=float) / s.scale
    try:
        U, chisqr, models, ok = _levenberg_marquardt(pr, Y, pr.internal(X0))
    except FrictionLabError:
        return None
    return Refits(chisqr=chisqr, values=pr.values(pr.external(U)), models=models, ok=ok)


def _residuals(pr: Problem, U: np.ndarray, Y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(models (m, n), weighted residuals (m, n)) at internal values U (m, k) against rows Y (m, n)."""
    M = pr.predict(pr.external(U))
    if M is None:
        raise FrictionLabError("batch prediction refused")
    return M, (M - Y) / pr.sigma


def _levenberg_marquardt(pr: Problem, Y: np.ndarray, U: np.ndarray):
    """Every row's Levenberg-Marquardt run, stepped together; returns (U, chisqr, models, ok) per row. Each
    step predicts, in one batch, the trial point of every running row and the forward-difference neighbours
    it needs if accepted, so an accepted step comes with its Jacobian."""
    r, k = U.shape
    U = U.copy()
    models, res, J = _with_jacobian(pr, U, Y)
    chisqr = np.einsum("ij,ij->i", res, res)
    ok = np.isfinite(chisqr) & np.isfinite(J).all(axis=(1, 2))
    lam, nu = np.full(r, LAMBDA0), np.full(r, 2.0)
    running = ok.copy()
    for _ in range(MAX_STEPS):
        idx = np.nonzero(running)[0]
        g, A = np.einsum("rnk,rn->rk", J[idx], res[idx]), np.einsum("rnk,rnl->rkl", J[idx], J[idx])
        gain = _gauss_newton_gain(g, A)
        at_min = gain <= FTOL * np.maximum(chisqr[idx], 1.0)  # chi-square is in sigma^2: below 1, absolute
        running[idx[at_min]] = False
        idx, g, A, gain = idx[~at_min], g[~at_min], A[~at_min], gain[~at_min]
        if not idx.size:
            break
        D = np.einsum("rkk->rk", A)
        D = np.maximum(D, 1e-12 * np.max(D, axis=1, keepdims=True) + 1e-300)
        step = -np.linalg.solve(A + lam[idx, None, None] * _diag(D), g[..., None])[..., 0]
        trial = U[idx] + step
        m_new, r_new, J_new = _with_jacobian(pr, trial, Y[idx])
        c_new = np.einsum("ij,ij->i", r_new, r_new)
        finite = np.isfinite(c_new) & np.isfinite(J_new).all(axis=(1, 2))
        lost = idx[~finite]  # a step or its neighbours the law refuses: handed back, refitted alone
        ok[lost], running[lost] = False, False
        better = finite & (c_new < chisqr[idx])
        # Nielsen's damping: after a step, by how well the quadratic model predicted its fall in chi-square (a
        # large-residual fit, such as the series far from its range, overshoots with Gauss-Newton steps)
        pred = -2.0 * np.einsum("rk,rk->r", step, g) - np.einsum("rk,rkl,rl->r", step, A, step)
        with np.errstate(all="ignore"):
            rho = (chisqr[idx] - c_new) / pred  # read for accepted steps only, whose fall and promise are > 0
        go = idx[better]
        U[go], chisqr[go], models[go], res[go], J[go] = trial[better], c_new[better], m_new[better], r_new[better], \
            J_new[better]
        lam[go] *= np.maximum(1.0 / 3.0, 1.0 - (2.0 * rho[better] - 1.0) ** 3)
        lam[go] = np.maximum(lam[go], 1e-15)
        nu[go] = 2.0
        stay = idx[~better & finite]
        lam[stay] *= nu[stay]
        nu[stay] *= 2.0
        # no damped step lowers chi-square, or none where what a step promises is below the forward differences'
        # resolution: at the minimum
        resolved = gain[~better & finite] <= RESOLVED * np.maximum(chisqr[stay], 1.0)
        running[stay[(lam[stay] > LAMBDA_MAX) | resolved]] = False
        # a step below XTOL of the values (MINPACK's xtol): at the minimum, or at a kink of chi-square (a stick time
        # crossing a sample time) that smaller steps do not resolve
        running[idx[finite & np.all(np.abs(step) <= XTOL * (np.abs(U[idx]) + XTOL), axis=1)]] = False
    else:
        ok &= ~running  # still going after MAX_STEPS: not converged
    ok &= np.isfinite(chisqr) & np.isfinite(models).all(axis=1)
    return U, chisqr, models, ok


def _diag(D: np.ndarray) -> np.ndarray:
    out = np.zeros(D.shape + (D.shape[-1],))
    idx = np.arange(D.shape[-1])
    out[:, idx, idx] = D
    return out


def _steps(U: np.ndarray) -> np.ndarray:
    """lmfit's (MINPACK's) forward-difference steps: STEP |u|, or STEP where u is 0."""
    h = STEP * np.abs(U)
    return np.where(h == 0.0, STEP, h)


def _with_jacobian(pr: Problem, U: np.ndarray, Y: np.ndarray):
    """(models (r, n), weighted residuals (r, n), their forward-difference Jacobians (r, n, k)) at internal values
    U (r, k) against rows Y (r, n): every point and its k neighbours in one batched prediction."""
    r, k = U.shape
    h = _steps(U)
    pts = np.concatenate([U[:, None, :], U[:, None, :] + h[:, :, None] * np.eye(k)], axis=1)
    M, R = _residuals(pr, pts.reshape(-1, k), np.repeat(Y, k + 1, axis=0))
    M, R = M.reshape(r, k + 1, -1), R.reshape(r, k + 1, -1)
    return M[:, 0], R[:, 0], np.transpose((R[:, 1:] - R[:, :1]) / h[:, :, None], (0, 2, 1))


def _gauss_newton_gain(g: np.ndarray, A: np.ndarray) -> np.ndarray:
    """The fall in chi-square a full Gauss-Newton step promises, g^T A^+ g per row (nan rows: inf)."""
    with np.errstate(all="ignore"):
        gain = np.einsum("rk,rk->r", g, np.einsum("rkl,rl->rk", np.linalg.pinv(A), g))
    return np.where(np.isfinite(gain), gain, np.inf)
