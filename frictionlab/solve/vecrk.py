"""A vectorized explicit Runge-Kutta integrator for many independent ODE problems at once.

Each problem (a column of the state array, shape (n_states, n_problems)) has its own time,
step size and step control, exactly as scipy's RK45/DOP853 would take them alone; one
iteration advances every unfinished problem by one step attempt with array operations over
the batch. Output at requested times comes from each method's dense output, and a terminal
event g(t, y) = 0 (crossing from g > 0 to g <= 0) is located per problem on the dense output.
The Butcher tableaus are the published ones (``rktableau``: Dormand-Prince 5(4) and Hairer's DOP853, the
numbers scipy's RK45 and DOP853 take), so the same tolerances mean the same local error control. Stage
combinations add the nonzero terms in order (not BLAS or einsum, whose order depends on the batch's size), so a
problem's numbers do not depend on the other problems in its batch. With one output grid for all problems, each step's
outputs are one padded block of dense-output evaluations. Knows nothing about friction.
"""
from __future__ import annotations

import attrs
import numpy as np
from ..core.errors import SolverError
from .rktableau import DOP853, RK45
from .vecdense import dense_output, fill_at_start, fill_dense, has_outputs, rows_dot, vec_dot

METHODS = ("RK45", "DOP853")
SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0
MAX_ITERATIONS = 200_000
BISECTIONS = 60  # event location: interval shrinks by 2^-60, below double resolution
EPS4 = 1 + 4 * np.finfo(float).eps


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


def _rms(x):
    return np.sqrt(np.mean(x * x, axis=0))


class _Run:
    """One ``integrate`` call: every problem's time, state, step and output pointer; ``step`` advances the
    unfinished ones by one step attempt."""

    def __init__(self, make_rhs, t0, y0, t_end, t_out, method, rtol, atol, make_event, breaks, out):
        if method not in METHODS:
            raise SolverError(f"batch: unknown method {method!r}; choose one of {', '.join(METHODS)}")
        self.cls = cls = {"RK45": RK45, "DOP853": DOP853}[method]
        self.method, self.make_rhs, self.make_event, self.breaks = method, make_rhs, make_event, breaks
        self.rtol, self.atol = rtol, rtol if atol is None else atol
        t0 = np.asarray(t0, dtype=float)
        self.y = y = np.array(y0, dtype=float)
        d, n = y.shape
        self.t_end = np.broadcast_to(np.asarray(t_end, dtype=float), (n,))
        t_out = np.asarray(t_out, dtype=float)
        self.m = m = t_out.shape[-1]
        self.shared = shared = t_out if t_out.ndim == 1 else (t_out[0] if np.all(t_out == t_out[:1]) else None)
        self.t_out = shared[None, :] if shared is not None else t_out  # one grid: row 0 for every problem (``times``)
        self.Y = np.full((d, n, m), np.nan) if out is None else out
        if out is not None:
            assert out.shape == (d, n, m) and all(o.flags.c_contiguous for o in out)  # written through flat views
            self.Y.fill(np.nan)
        self.t_event = np.full(n, np.nan)
        self.y_event = np.full((d, n), np.nan)
        self.nfev = np.zeros(n, dtype=np.int64)
        # next output index per problem: first t_out >= t0 (outputs exactly at t0 are the initial state)
        self.ptr = np.searchsorted(shared, t0, side="left") if shared is not None else (self.t_out < t0[:, None]).sum(axis=1)
        self.t = t0.copy()
        self.active = np.nonzero(self.t < self.t_end)[0]
        self.ptr0 = self.ptr.copy()  # outputs are filled contiguously from here: reached is [ptr0, ptr) at the end
        fill_at_start(self.Y, self.ptr, self.t_out, self.t, y)
        self.iterations = 0
        self.exponent = -1.0 / (cls.error_estimator_order + 1)
        self.nk = cls.n_stages + 1 + (len(cls.C_EXTRA) if cls is DOP853 else 0)  # stages, f_new, DOP853's extras
        self.E = np.array([cls.E5, cls.E3]) if cls is DOP853 else cls.E[None]

    def result(self) -> Result:
        return Result(self.Y, _reached(self.ptr0, self.ptr, self.m), self.t_event, self.y_event, self.nfev,
                      self.iterations)

    def start(self):
        """The right-hand side, event and first step of every active problem (scipy's initial step)."""
        t, y, active, breaks = self.t, self.y, self.active, self.breaks
        d, n = y.shape
        self.rhs = rhs = self.make_rhs(active)
        self.g = g = self.make_event(active) if self.make_event else None
        f = rhs(t[active], y[:, active])
        self.nfev[active] += 1
        g_old = g(t[active], y[:, active]) if g else None
        h = _initial_step(rhs, t[active], y[:, active], f, self.t_end[active] - t[active], self.cls.order, self.rtol,
                          self.atol)
        if breaks is not None:  # a first step that would cross a break is sized to reach it
            h = np.minimum(h, np.where(breaks[active] > t[active, None], breaks[active] - t[active, None],
                                       np.inf).min(axis=1))
        self.nfev[active] += 1
        self.F = np.empty((d, n))
        self.F[:, active] = f
        self.H = np.zeros(n)
        self.H[active] = h
        self.Gold = np.full(n, np.nan)
        if g:
            self.Gold[active] = g_old
        self.rejected = np.zeros(n, dtype=bool)

    def _step_size(self, ta):
        """This attempt's steps: the proposed ones, cut at the end and at the next break; underflow is an error."""
        active, t, breaks = self.active, self.t, self.breaks
        ha = np.minimum(self.H[active], self.t_end[active] - ta)
        if breaks is not None:
            b = breaks[active]
            ahead = np.where(b > ta[:, None] * EPS4, b, np.inf).min(axis=1)
            np.minimum(ha, ahead - ta, out=ha)
        min_step = 10.0 * np.abs(np.nextafter(ta, np.inf) - ta)
        if np.any(ha < min_step):
            bad = active[np.argmax(ha < min_step)]
            raise SolverError(f"batch {self.method}: step size underflow in problem {bad} at t = {t[bad]:g}")
        return ha

    def _attempt(self, ta, ya, ha):
        """The stages of one step as scipy's rk_step takes them (dy = h (K[:s]^T a), one product per stage):
        (stages K, y_new, f_new, error norm)."""
        cls, rhs, active = self.cls, self.rhs, self.active
        d, k = ya.shape
        A, B, C, ns = cls.A, cls.B, cls.C, cls.n_stages
        K = np.empty((self.nk, d, k))
        Kf = K.reshape(self.nk, d * k)
        tmp = np.empty(d * k)  # scratch row of the stage combinations
        np.take(self.F, active, axis=1, out=K[0])
        for s in range(1, ns):
            dy = vec_dot(A[s, :s], Kf[:s], tmp=tmp).reshape(d, k)
            dy *= ha
            dy += ya
            K[s] = rhs(ta + C[s] * ha, dy)
        y_new = vec_dot(B, Kf[:ns], tmp=tmp).reshape(d, k)
        y_new *= ha
        y_new += ya
        K[ns] = f_new = rhs(ta + ha, y_new)
        self.nfev[active] += ns
        scale = np.maximum(np.abs(ya), np.abs(y_new))
        scale *= self.rtol
        scale += self.atol
        err = _error_norm(cls, rows_dot(self.E, Kf[: ns + 1], tmp=tmp).reshape(len(self.E), d, k), ha, scale)
        return K, y_new, f_new, err

    def step(self):
        """One step attempt of every unfinished problem: accepted steps move on, fill outputs and locate events."""
        self.iterations += 1
        if self.iterations > MAX_ITERATIONS:
            raise SolverError(f"batch {self.method}: more than {MAX_ITERATIONS} steps; the problem is stiff or singular")
        active = self.active
        ta, ya = self.t[active], self.y[:, active]
        ha = self._step_size(ta)
        K, y_new, f_new, err = self._attempt(ta, ya, ha)
        t_new = ta + ha
        ok = err < 1.0
        with np.errstate(divide="ignore"):
            factor = np.where(err == 0.0, MAX_FACTOR, SAFETY * np.float_power(err, self.exponent))  # libm pow, as scipy
        factor = np.where(ok, np.minimum(MAX_FACTOR, factor), np.maximum(MIN_FACTOR, factor))
        factor = np.where(ok & self.rejected[active], np.minimum(1.0, factor), factor)
        self.H[active] = ha * factor
        self.rejected[active] = ~ok
        acc = np.nonzero(ok)[0]
        if acc.size:
            self._accept(acc, ta, ya, ha, K, y_new, t_new, f_new)

    def _accept(self, acc, ta, ya, ha, K, y_new, t_new, f_new):
        """Accepted steps (rows acc of the active set): events, outputs on the dense output, the new states."""
        active, g = self.active, self.g
        k = active.size
        ia = active[acc]
        stop = np.zeros(acc.size, dtype=bool)
        if g:
            g_new = g(t_new, y_new)[acc]
            stop = (g_new <= 0.0) & (self.Gold[ia] > 0.0)
            self.Gold[ia] = g_new
        needs_dense = stop | has_outputs(self.t_out, self.ptr, ia, t_new[acc])
        if needs_dense.any():
            dense = dense_output(self.cls, self.rhs, K, ta, ha, ya, y_new, f_new)
            if self.cls is DOP853:
                self.nfev[active] += 3
            t_stop_acc = t_new[acc]
            if stop.any():
                je = np.nonzero(stop)[0]
                ts, ys = _locate(self.make_event, ia[je], dense, acc[je], ta[acc[je]], ha[acc[je]])
                t_stop_acc = t_stop_acc.copy()
                t_stop_acc[je] = ts
                self.t_event[ia[je]] = ts
                self.y_event[:, ia[je]] = ys
            jd = np.nonzero(needs_dense)[0]
            fill_dense(self.Y, self.ptr, self.t_out, ia[jd], acc[jd], t_stop_acc[jd], dense, self.shared)
        if acc.size == k:
            self.t[ia] = t_new
            self.y[:, ia] = y_new
            self.F[:, ia] = f_new
        else:
            self.t[ia] = t_new[acc]
            self.y[:, ia] = y_new[:, acc]
            self.F[:, ia] = f_new[:, acc]
        done = stop | (t_new[acc] >= self.t_end[ia])
        if done.any():
            keep = np.ones(k, dtype=bool)
            keep[acc[done]] = False
            self.active = active = active[keep]
            if active.size:
                self.rhs = self.make_rhs(active)
                self.g = self.make_event(active) if self.make_event else None


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
    run = _Run(make_rhs, t0, y0, t_end, t_out, method, rtol, atol, make_event, breaks, out)
    if run.active.size:
        run.start()
        while run.active.size:
            run.step()
    return run.result()


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
    """The starting step of Hairer, Norsett and Wanner (Solving ODEs I, section II.4; scipy's solvers start the
    same way), per problem."""
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
