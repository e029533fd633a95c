"""Stage combinations in a fixed order and the dense output of ``vecrk``'s steps, evaluated at the problems'
output times."""
from __future__ import annotations

import numpy as np
from .rktableau import RK45


def rows_dot(M, K, out=None, tmp=None):
    """M @ K, row by row (see ``vec_dot``)."""
    out = np.empty((M.shape[0], K.shape[1])) if out is None else out
    tmp = np.empty(K.shape[1]) if tmp is None else tmp
    for i, row in enumerate(M):
        vec_dot(row, K, out[i], tmp)
    return out


def vec_dot(a, K, out=None, tmp=None):
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


def times(t_out, rows, cols):
    """t_out[rows, cols] of an (n, m) grid, or of one grid for all problems (a (1, m) row)."""
    return t_out[0, cols] if t_out.shape[0] == 1 else t_out[rows, cols]


def has_outputs(t_out, ptr, idx, t_new):
    m = t_out.shape[1]
    p = np.minimum(ptr[idx], m - 1)
    return (ptr[idx] < m) & (times(t_out, idx, p) <= t_new)


class Dense:
    """Dense output over the steps [t_old, t_old + h] of the active problems.

    Coefficients are stored as (d, n_coef, k) so that evaluating many output times per problem is a
    Horner scheme on (d, q, c) arrays broadcast from the problems' coefficients, with no gathering
    per output time."""

    def __init__(self, kind, t_old, h, y_old, coef):
        self.kind, self.t_old, self.h, self.y_old = kind, t_old, h, y_old
        self.coef = coef.transpose(1, 0, 2)  # (d, nc, k) view

    def subset(self, rows) -> "Dense":
        """The dense output of rows only (so repeated calls need no gathering)."""
        out = object.__new__(Dense)
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


def dense_output(cls, rhs, K, t_old, h, y_old, y_new, f_new):
    """Dense output of the steps just taken by the whole active set (rejected rows are never read).

    K (n_k, d, k) holds the stages and f_new; DOP853's extra stages are written into its last rows."""
    nk, d, k = K.shape
    Kf = K.reshape(nk, d * k)
    if cls is RK45:
        return Dense("RK45", t_old, h, y_old, rows_dot(cls.P.T, Kf[: cls.n_stages + 1]).reshape(-1, d, k))
    s0 = cls.n_stages + 1
    for j, (a, c) in enumerate(zip(cls.A_EXTRA, cls.C_EXTRA)):
        s = s0 + j
        dy = vec_dot(a[:s], Kf[:s]).reshape(d, k)
        dy *= h
        dy += y_old
        K[s] = rhs(t_old + c * h, dy)
    Fc = np.empty((3 + len(cls.D), d, k))  # DOP853's interpolant: 7 coefficient rows
    dyv = np.subtract(y_new, y_old, out=Fc[0])
    np.multiply(K[0], h, out=Fc[1])
    Fc[1] -= dyv
    np.add(f_new, K[0], out=Fc[2])
    Fc[2] *= -h
    Fc[2] += 2 * dyv
    rows_dot(cls.D, Kf, out=Fc[3:].reshape(len(cls.D), d * k))
    Fc[3:] *= h
    return Dense("DOP853", t_old, h, y_old, Fc)


def fill_at_start(Y, ptr, t_out, t, y):
    """Outputs requested exactly at each problem's start time take its initial state."""
    m = t_out.shape[1]
    rows = np.nonzero((ptr < m))[0]
    if rows.size == 0:
        return
    at = times(t_out, rows, ptr[rows]) == t[rows]
    r = rows[at]
    Y[:, r, ptr[r]] = y[:, r]
    ptr[r] += 1


def fill_dense(Y, ptr, t_out, idx, pos, t_stop, dense, shared=None):
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
