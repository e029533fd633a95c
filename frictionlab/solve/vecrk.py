"""A vectorized explicit Runge-Kutta integrator for many independent ODE problems at once.

Each problem (a column of the state array, shape (n_states, n_problems)) has its own time,
step size and step control, exactly as scipy's RK45/DOP853 would take them alone; one
iteration advances every unfinished problem by one step attempt with array operations over
the batch. Output at requested times comes from each method's dense output, and a terminal
event g(t, y) = 0 (crossing from g > 0 to g <= 0) is located per problem on the dense output.
The Butcher tableaus are scipy's (``scipy.integrate.RK45`` and ``DOP853`` class attributes),
so the same tolerances mean the same local error control. Stage combinations add the nonzero terms
in order (not BLAS or einsum, whose order depends on the batch's size), so a problem's numbers do
not depend on the other problems in its batch. With one output grid for all problems, each step's
outputs are one padded block of dense-output evaluations. Knows nothing about friction.
"""
from __future__ import annotations

import attrs
import numpy as np
from scipy.integrate import DOP853, RK45

from ..core.errors import SolverError

METHODS = ("RK45", "DOP853")
SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0
MAX_ITERATIONS = 200_000
BISECTIONS = 60  # event location: interval shrinks by 2^-60, below double resolution


@attrs.frozen
class Result:
    """Outputs of ``integrate``: Y (n_states, n, m) where reached (else NaN), reached (n, m) bool,
    t_event (n,) (NaN where no event), y_event (n_states, n), and counters. ``scaled``: Y is in the
    problem's (scaled) units, as y_event always is; False where a caller's engine wrote it unscaled
    (``frictionlab.solve.compiled``)."""

    Y: np.ndarray
    reached: np.ndarray
    t_event: np.ndarray
    y_event: np.ndarray
    nfev: np.ndarray  # per problem
    iterations: int
    scaled: bool = True


def _rows_dot(M, K, out=None, tmp=None):
    """M @ K, row by row (see ``_vec_dot``)."""
    out = np.empty((M.shape[0], K.shape[1])) if out is None else out
    tmp = np.empty(K.shape[1]) if tmp is None else tmp
    for i, row in enumerate(M):
        _vec_dot(row, K, out[i], tmp)
    return out


def _vec_dot(a, K, out=None, tmp=None):
    """a @ K for a (s,), K (s, n): the terms of nonzero coefficients added in order, in place (tmp: a
    scratch row).

    Not BLAS or einsum: those may start threads (on a shared machine costing several times the CPU they
    save) and sum in an order that depends on n, so a scene's result would depend on its batch's size."""
    out = np.empty(K.shape[1]) if out is None else out
    first = True
    for j, c in enumerate(a.tolist()):
        if c == 0.0:
            continue
        if first:
            np.multiply(K[j], c, out=out)
            first = False
        else:
            if tmp is None:
                tmp = np.empty_like(out)
            np.multiply(K[j], c, out=tmp)
            out += tmp
    if first:
        out.fill(0.0)
    return out


def _rms(x):
    return np.sqrt(np.mean(x * x, axis=0))


def integrate(make_rhs, t0, y0, t_end, t_out, method: str = "DOP853", rtol: float = 1e-8, atol: float | None = None,
              make_event=None, breaks=None, out=None) -> Result:
    """Integrate n problems y' = f(t, y) from t0 (n,) with y0 (d, n) to t_end (n,).

    make_rhs(idx) returns rhs(t, y) for the problems ``idx`` (t (k,), y (d, k) -> (d, k)); it is
    called once whenever the set of unfinished problems changes. t_out (n, m) holds each
    problem's increasing output times, or (m,) one grid for all of them (entries outside [t0, t_end] are never filled).
    make_event(idx), if given, returns g(t, y) -> (k,); a problem stops where g crosses to <= 0.
    breaks (n, nb), if given, are times where f has a kink or jump (e.g. the end of contact): no step
    crosses one, so a short forcing window before it cannot be stepped over. out (n_states, n, m), each
    out[j] C-contiguous, if given, receives the outputs (a view into a caller's larger array).
    """
    if method not in METHODS:
        raise SolverError(f"batch: unknown method {method!r}; choose one of {', '.join(METHODS)}")
    cls = {"RK45": RK45, "DOP853": DOP853}[method]
    atol = rtol if atol is None else atol
    t0 = np.asarray(t0, dtype=float)
    y = np.array(y0, dtype=float)
    d, n = y.shape
    t_end = np.broadcast_to(np.asarray(t_end, dtype=float), (n,))
    t_out = np.asarray(t_out, dtype=float)
    m = t_out.shape[-1]
    shared = t_out if t_out.ndim == 1 else (t_out[0] if np.all(t_out == t_out[:1]) else None)  # one grid for all
    if shared is not None:
        t_out = shared[None, :]  # indexed as row 0 for every problem (``_times``)
    Y = np.full((d, n, m), np.nan) if out is None else out
    if out is not None:
        assert out.shape == (d, n, m) and all(o.flags.c_contiguous for o in out)  # written through flat views
        Y.fill(np.nan)
    t_event = np.full(n, np.nan)
    y_event = np.full((d, n), np.nan)
    nfev = np.zeros(n, dtype=np.int64)
    # next output index per problem: first t_out >= t0 (outputs exactly at t0 are the initial state)
    ptr = np.searchsorted(shared, t0, side="left") if shared is not None else (t_out < t0[:, None]).sum(axis=1)
    t = t0.copy()
    active = np.nonzero(t < t_end)[0]
    ptr0 = ptr.copy()  # outputs are filled contiguously from here: reached is [ptr0, ptr) at the end
    _fill_at_start(Y, ptr, t_out, t, y)
    if active.size == 0:
        return Result(Y, _reached(ptr0, ptr, m), t_event, y_event, nfev, 0)

    order = cls.error_estimator_order
    exponent = -1.0 / (order + 1)
    A, B, C = cls.A, cls.B, cls.C
    ns = cls.n_stages
    nk = ns + 1 + (len(cls.C_EXTRA) if cls is DOP853 else 0)  # stages, f_new, DOP853's extra dense stages
    E = np.array([cls.E5, cls.E3]) if cls is DOP853 else cls.E[None]
    rhs = make_rhs(active)
    g = make_event(active) if make_event else None
    f = rhs(t[active], y[:, active])
    nfev[active] += 1
    g_old = g(t[active], y[:, active]) if g else None
    h = _initial_step(rhs, t[active], y[:, active], f, t_end[active] - t[active], cls.order, rtol, atol)
    if breaks is not None:  # a first step that would cross a break is sized to reach it
        h = np.minimum(h, np.where(breaks[active] > t[active, None], breaks[active] - t[active, None], np.inf).min(axis=1))
    nfev[active] += 1
    F = np.empty((d, n))
    F[:, active] = f
    H = np.zeros(n)
    H[active] = h
    Gold = np.full(n, np.nan)
    if g:
        Gold[active] = g_old
    rejected = np.zeros(n, dtype=bool)
    iterations = 0
    eps4 = 1 + 4 * np.finfo(float).eps
    while active.size:
        iterations += 1
        if iterations > MAX_ITERATIONS:
            raise SolverError(f"batch {method}: more than {MAX_ITERATIONS} steps; the problem is stiff or singular")
        k = active.size
        ta, ya = t[active], y[:, active]
        ha = np.minimum(H[active], t_end[active] - ta)
        if breaks is not None:
            b = breaks[active]
            ahead = np.where(b > ta[:, None] * eps4, b, np.inf).min(axis=1)
            np.minimum(ha, ahead - ta, out=ha)
        min_step = 10.0 * np.abs(np.nextafter(ta, np.inf) - ta)
        if np.any(ha < min_step):
            bad = active[np.argmax(ha < min_step)]
            raise SolverError(f"batch {method}: step size underflow in problem {bad} at t = {t[bad]:g}")
        # stages as scipy's rk_step takes them: dy = h (K[:s]^T a), one matrix product per stage
        K = np.empty((nk, d, k))
        Kf = K.reshape(nk, d * k)
        tmp = np.empty(d * k)  # scratch row of the stage combinations
        np.take(F, active, axis=1, out=K[0])
        for s in range(1, ns):
            dy = _vec_dot(A[s, :s], Kf[:s], tmp=tmp).reshape(d, k)
            dy *= ha
            dy += ya
            K[s] = rhs(ta + C[s] * ha, dy)
        y_new = _vec_dot(B, Kf[:ns], tmp=tmp).reshape(d, k)
        y_new *= ha
        y_new += ya
        t_new = ta + ha
        K[ns] = f_new = rhs(t_new, y_new)
        nfev[active] += ns
        scale = np.maximum(np.abs(ya), np.abs(y_new))
        scale *= rtol
        scale += atol
        err = _error_norm(cls, _rows_dot(E, Kf[: ns + 1], tmp=tmp).reshape(len(E), d, k), ha, scale)
        ok = err < 1.0
        with np.errstate(divide="ignore"):
            factor = np.where(err == 0.0, MAX_FACTOR, SAFETY * np.float_power(err, exponent))  # libm pow, as scipy
        factor = np.where(ok, np.minimum(MAX_FACTOR, factor), np.maximum(MIN_FACTOR, factor))
        factor = np.where(ok & rejected[active], np.minimum(1.0, factor), factor)
        H[active] = ha * factor
        rejected[active] = ~ok
        acc = np.nonzero(ok)[0]
        if acc.size == 0:
            continue
        ia = active[acc]
        stop = np.zeros(acc.size, dtype=bool)
        if g:
            g_new = g(t_new, y_new)[acc]
            stop = (g_new <= 0.0) & (Gold[ia] > 0.0)
            Gold[ia] = g_new
        needs_dense = stop | _has_outputs(t_out, ptr, ia, t_new[acc])
        if needs_dense.any():
            dense = _dense(cls, rhs, K, ta, ha, ya, y_new, f_new)
            if cls is DOP853:
                nfev[active] += 3
            t_stop_acc = t_new[acc]
            if stop.any():
                je = np.nonzero(stop)[0]
                ts, ys = _locate(make_event, ia[je], dense, acc[je], ta[acc[je]], ha[acc[je]])
                t_stop_acc = t_stop_acc.copy()
                t_stop_acc[je] = ts
                t_event[ia[je]] = ts
                y_event[:, ia[je]] = ys
            jd = np.nonzero(needs_dense)[0]
            _fill_dense(Y, ptr, t_out, ia[jd], acc[jd], t_stop_acc[jd], dense, shared)
        if acc.size == k:
            t[ia] = t_new
            y[:, ia] = y_new
            F[:, ia] = f_new
        else:
            t[ia] = t_new[acc]
            y[:, ia] = y_new[:, acc]
            F[:, ia] = f_new[:, acc]
        done = stop | (t_new[acc] >= t_end[ia])
        if done.any():
            keep = np.ones(active.size, dtype=bool)
            keep[acc[done]] = False
            active = active[keep]
            if active.size:
                rhs = make_rhs(active)
                g = make_event(active) if make_event else None
    return Result(Y, _reached(ptr0, ptr, m), t_event, y_event, nfev, iterations)


def _reached(ptr0, ptr, m):
    k = np.arange(m)[None, :]
    return (k >= ptr0[:, None]) & (k < ptr[:, None])


def _error_norm(cls, errs, h, scale):
    """scipy's error norms per problem from the error combinations errs (DOP853: E5, E3; RK45: E) of the stages."""
    if cls is DOP853:
        err5 = errs[0] / scale
        err3 = errs[1] / scale
        e5 = np.sum(err5 * err5, axis=0)  # row by row: the same order whatever the batch's size
        e3 = np.sum(err3 * err3, axis=0)
        denom = e5 + 0.01 * e3
        with np.errstate(invalid="ignore", divide="ignore"):
            out = np.abs(h) * e5 / np.sqrt(denom * scale.shape[0])
        return np.where(denom > 0, out, 0.0)
    return _rms(errs[0] * h / scale)


def _initial_step(rhs, t0, y0, f0, span, order, rtol, atol):
    """scipy's select_initial_step (Hairer, Norsett and Wanner, II.4), per problem."""
    scale = atol + np.abs(y0) * rtol
    d0, d1 = _rms(y0 / scale), _rms(f0 / scale)
    h0 = np.where((d0 < 1e-5) | (d1 < 1e-5), 1e-6, 0.01 * d0 / np.where(d1 > 0, d1, 1.0))
    h0 = np.minimum(h0, span)
    f1 = rhs(t0 + h0, y0 + h0 * f0)
    d2 = _rms((f1 - f0) / scale) / h0
    big = np.maximum(d1, d2)
    with np.errstate(divide="ignore"):
        h1 = np.where(big <= 1e-15, np.maximum(1e-6, h0 * 1e-3), (0.01 / np.where(big > 0, big, 1.0)) ** (1.0 / (order + 1)))
    return np.minimum(np.minimum(100 * h0, h1), span)


def _times(t_out, rows, cols):
    """t_out[rows, cols] of an (n, m) grid, or of one grid for all problems (a (1, m) row)."""
    return t_out[0, cols] if t_out.shape[0] == 1 else t_out[rows, cols]


def _has_outputs(t_out, ptr, idx, t_new):
    m = t_out.shape[1]
    p = np.minimum(ptr[idx], m - 1)
    return (ptr[idx] < m) & (_times(t_out, idx, p) <= t_new)


class _Dense:
    """Dense output over the steps [t_old, t_old + h] of the active problems.

    Coefficients are stored as (d, n_coef, k) so that evaluating many output times per problem is a
    Horner scheme on (d, q, c) arrays broadcast from the problems' coefficients, with no gathering
    per output time."""

    def __init__(self, kind, t_old, h, y_old, coef):
        self.kind, self.t_old, self.h, self.y_old = kind, t_old, h, y_old
        self.coef = coef.transpose(1, 0, 2)  # (d, nc, k) view

    def subset(self, rows) -> "_Dense":
        """The dense output of rows only (so repeated calls need no gathering)."""
        out = object.__new__(_Dense)
        out.kind = self.kind
        out.t_old, out.h, out.y_old, out.coef = self.t_old[rows], self.h[rows], self.y_old[:, rows], self.coef[:, :, rows]
        return out

    def __call__(self, x, rows=None):
        """States at fractions x of the step, x (q,) or (q, c), for problems rows (q,) (None: all) -> (d,) + x.shape."""
        if rows is None:
            C, y0, h = self.coef, self.y_old, self.h
        else:
            C, y0, h = self.coef[:, :, rows], self.y_old[:, rows], self.h[rows]
        nc = C.shape[1]
        if x.ndim == 2:
            C, y0, h = C[..., None], y0[..., None], h[:, None]
        acc = C[:, nc - 1] * x
        if self.kind == "RK45":  # y_old + h * sum_j Q_j x^(j+1)
            for j in range(nc - 2, -1, -1):
                acc += C[:, j]
                acc *= x
            acc *= h
        else:  # DOP853: nested x, (1 - x) products
            om = 1.0 - x
            for i, j in enumerate(range(nc - 2, -1, -1), start=1):
                acc += C[:, j]
                acc *= x if i % 2 == 0 else om
        acc += y0
        return acc


def _dense(cls, rhs, K, t_old, h, y_old, y_new, f_new):
    """Dense output of the steps just taken by the whole active set (rejected rows are never read).

    K (n_k, d, k) holds the stages and f_new; DOP853's extra stages are written into its last rows."""
    nk, d, k = K.shape
    Kf = K.reshape(nk, d * k)
    if cls is RK45:
        return _Dense("RK45", t_old, h, y_old, _rows_dot(cls.P.T, Kf[: cls.n_stages + 1]).reshape(-1, d, k))
    from scipy.integrate._ivp import (
        dop853_coefficients as dc,  # INTERPOLATOR_POWER only
    )

    s0 = cls.n_stages + 1
    for j, (a, c) in enumerate(zip(cls.A_EXTRA, cls.C_EXTRA)):
        s = s0 + j
        dy = _vec_dot(a[:s], Kf[:s]).reshape(d, k)
        dy *= h
        dy += y_old
        K[s] = rhs(t_old + c * h, dy)
    Fc = np.empty((dc.INTERPOLATOR_POWER, d, k))
    dyv = np.subtract(y_new, y_old, out=Fc[0])
    np.multiply(K[0], h, out=Fc[1])
    Fc[1] -= dyv
    np.add(f_new, K[0], out=Fc[2])
    Fc[2] *= -h
    Fc[2] += 2 * dyv
    _rows_dot(cls.D, Kf, out=Fc[3:].reshape(len(cls.D), d * k))
    Fc[3:] *= h
    return _Dense("DOP853", t_old, h, y_old, Fc)


def _fill_at_start(Y, ptr, t_out, t, y):
    """Outputs requested exactly at each problem's start time take its initial state."""
    m = t_out.shape[1]
    rows = np.nonzero((ptr < m))[0]
    if rows.size == 0:
        return
    at = _times(t_out, rows, ptr[rows]) == t[rows]
    r = rows[at]
    Y[:, r, ptr[r]] = y[:, r]
    ptr[r] += 1


def _fill_dense(Y, ptr, t_out, idx, pos, t_stop, dense, shared=None):
    """Fill every output t_out[i, ptr_i:] <= t_stop_i of problems idx (rows pos of the dense output)."""
    start = ptr[idx]
    m = t_out.shape[1]
    Yf = [y.reshape(-1) for y in Y]  # each Y[j] C-contiguous (n, m): flat views
    if shared is not None:  # one grid for all problems: each problem's outputs here are columns start..stop-1
        stop = np.maximum(np.searchsorted(shared, t_stop, side="right"), start)
        counts = stop - start
        width = int(counts.max(initial=0))
        if width == 0:
            return
        keep = counts > 0
        if not keep.all():
            idx, pos, start, counts = idx[keep], pos[keep], start[keep], counts[keep]
        cols = start[:, None] + np.arange(width)[None, :]
        valid = cols < (start + counts)[:, None]
        np.minimum(cols, m - 1, out=cols)
        x = shared[cols]
        x -= dense.t_old[pos, None]
        x /= dense.h[pos, None]
        np.copyto(x, 0.0, where=~valid)  # padding beyond a problem's outputs: evaluated, never stored
        vals = dense(x, None if pos.size == dense.h.size and np.array_equal(pos, np.arange(pos.size)) else pos)
        flat = (idx[:, None] * m + cols).ravel()
        vals = vals.reshape(vals.shape[0], -1)
        if not valid.all():  # integer take and put: several times faster than boolean-mask indexing
            sel = np.flatnonzero(valid)
            flat, vals = flat[sel], np.take(vals, sel, axis=1)
        for j in range(len(Yf)):
            np.put(Yf[j], flat, vals[j])
        ptr[idx] = start + counts
        return
    within = (np.arange(m)[None, :] >= start[:, None]) & (t_out[idx] <= t_stop[:, None])
    rows, cols = np.nonzero(within)
    if rows.size == 0:
        return
    stop = within.sum(axis=1) + start
    tq = t_out[idx[rows], cols]
    p = pos[rows]
    x = (tq - dense.t_old[p]) / dense.h[p]
    vals, flat = dense(x, p), idx[rows] * m + cols
    for j in range(len(Yf)):
        np.put(Yf[j], flat, vals[j])
    ptr[idx] = np.maximum(ptr[idx], stop)


def root_bracketed(make_fn, lo, hi, glo, ghi, tol, gtol=0.0):
    """Per problem, the first point where fn <= 0 in brackets [lo, hi] with fn(lo) > 0 >= fn(hi).

    make_fn(rows) returns fn for the problems ``rows`` (it is rebuilt on the unfinished problems
    whenever half of them have converged). Regula falsi with the Anderson-Bjorck correction and
    the bracket kept; a bisection step wherever the secant leaves the bracket or the last three
    steps did not halve it. Returns the fn <= 0 end once the bracket is within tol, or once |fn|
    there is within gtol (the rounding noise of fn: no finer answer is meaningful).
    """
    n = np.size(lo)
    out = np.array(hi, dtype=float)
    cur = np.arange(n)
    lo, hi, glo, ghi = (np.array(a, dtype=float) for a in (lo, hi, glo, ghi))
    tol = np.broadcast_to(np.asarray(tol, dtype=float), (n,))
    gtol = np.broadcast_to(np.asarray(gtol, dtype=float), (n,))
    side = np.zeros(n)
    widths = [np.full(n, np.inf)] * 3
    fn = make_fn(cur)
    for it in range(BISECTIONS + 40):
        open_ = (hi - lo > tol) & (np.abs(ghi) > gtol)
        out[cur] = hi
        if not open_.any():
            break
        if open_.sum() <= cur.size // 2:  # drop the converged problems
            cur = cur[open_]
            lo, hi, glo, ghi, tol, gtol, side = (a[open_] for a in (lo, hi, glo, ghi, tol, gtol, side))
            widths = [w[open_] for w in widths]
            open_ = open_[open_]
            fn = make_fn(cur)
        with np.errstate(invalid="ignore", divide="ignore"):
            mid = (lo * ghi - hi * glo) / (ghi - glo)
        slow = (hi - lo) > 0.5 * widths[0]
        widths = widths[1:] + [hi - lo]
        bad = ~np.isfinite(mid) | slow | (it >= 30)
        mid = np.where(bad, 0.5 * (lo + hi), mid)
        # at least tol inside the bracket (as Brent's method steps): a secant that lands on an end whose
        # value is round-off (the root is that end) closes the bracket next time instead of bisecting on
        mid = np.where(hi - lo > 2 * tol, np.minimum(np.maximum(mid, lo + tol), hi - tol), 0.5 * (lo + hi))
        mid = np.where(open_, mid, hi)
        gm = fn(mid)
        below = (gm <= 0.0) & open_
        above = ~below & open_
        # the same end moved twice: scale the stale end's value (Anderson-Bjorck, m = 1 - g_new/g_replaced)
        with np.errstate(invalid="ignore", divide="ignore"):
            m_hi = np.where(below, 1.0 - gm / ghi, 0.5)
            m_lo = np.where(above, 1.0 - gm / glo, 0.5)
        m_hi = np.where(m_hi > 0, m_hi, 0.5)
        m_lo = np.where(m_lo > 0, m_lo, 0.5)
        hi, ghi = np.where(below, mid, hi), np.where(below, gm, ghi)
        lo, glo = np.where(above, mid, lo), np.where(above, gm, glo)
        glo = np.where(below & (side < 0), glo * m_hi, glo)
        ghi = np.where(above & (side > 0), ghi * m_lo, ghi)
        side = np.where(below, -1.0, np.where(above, 1.0, side))
    return out


def _locate(make_event, idx, dense, rows, t_old, h):
    """First g <= 0 within each step, on the dense output; returns (t_stop, y_stop)."""
    dense = dense.subset(rows)

    def make_fn(sub):
        g, dn, t0, hh = make_event(idx[sub]), dense.subset(sub), t_old[sub], h[sub]
        return lambda x: g(t0 + x * hh, dn(x))

    eps = np.finfo(float).eps
    fn = make_fn(np.arange(idx.size))
    lo, hi = np.zeros(idx.size), np.ones(idx.size)
    x = root_bracketed(make_fn, lo, hi, fn(lo), fn(hi), 4 * eps, 8 * eps)  # g is slip / its scale
    return t_old + x * h, dense(x)
