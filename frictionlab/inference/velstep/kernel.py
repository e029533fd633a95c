"""The velocity-step fit's inner sums, compiled (numba where it imports; ``core.jit``).

One pass over the samples of a dataset gives what Levenberg-Marquardt needs of the weighted, prewhitened
residual w and of five basis columns B (the four sensitivities dm/d(a, b, Dc, k) and a constant, each weighted and
prewhitened), without forming them: w'w, B'w, B'B, and their parts along the orthonormal columns Q of the linear
parameters (Q'w, Q'B). Every Jacobian column of the fit is a combination of the basis columns (C = B M,
``velstep.Problem.combination``), so that C'w = M'B'w, C'C = M'B'BM and Q'C = Q'BM, and the variable projection's
r'r = w'w - |Q'w|^2, J'r = C'w - (Q'C)'(Q'w) and J'J = C'C - (Q'C)'(Q'C) follow. Memory: nothing per sample.
The accumulators are scalars (held in registers), which makes the pass about three times faster than with small
arrays.
"""
import numpy as np

from ...core.jit import jit


@jit
def basis_sums(y, off, m, S, inv_sigma, phi, gain, Q):
    """Sums of one dataset (module docstring) for the residual z = (off + m - y) / sigma and the basis
    columns (S[:, 0], ..., S[:, 3], 1) / sigma, each prewhitened as w_i = (z_i - phi_i z_{i-1}) gain_i with
    gain_i = 1 / sqrt(1 - phi_i^2) (read only where phi_i != 0). Q: n x q orthonormal columns of the linear
    parameters, q <= 2 (the steady-state friction and the trend with slip). Returns (w'w, B'w (5,), B'B (5, 5), Q'w (q,), Q'B (q, 5))."""
    n = y.size
    q = Q.shape[1]
    ww = 0.0
    g0 = g1 = g2 = g3 = g4 = 0.0
    a00 = a10 = a11 = a20 = a21 = a22 = a30 = a31 = a32 = a33 = 0.0
    a40 = a41 = a42 = a43 = a44 = 0.0
    qw0 = q00 = q01 = q02 = q03 = q04 = 0.0
    qw1 = q10 = q11 = q12 = q13 = q14 = 0.0
    zp = p0 = p1 = p2 = p3 = p4 = 0.0
    for i in range(n):
        s = inv_sigma[i]
        z = (off + m[i] - y[i]) * s
        c0, c1, c2, c3, c4 = S[i, 0] * s, S[i, 1] * s, S[i, 2] * s, S[i, 3] * s, s
        f = phi[i]
        if f != 0.0:
            k = gain[i]
            w = (z - f * zp) * k
            d0, d1, d2 = (c0 - f * p0) * k, (c1 - f * p1) * k, (c2 - f * p2) * k
            d3, d4 = (c3 - f * p3) * k, (c4 - f * p4) * k
        else:
            w, d0, d1, d2, d3, d4 = z, c0, c1, c2, c3, c4
        zp, p0, p1, p2, p3, p4 = z, c0, c1, c2, c3, c4
        ww += w * w
        g0 += d0 * w
        g1 += d1 * w
        g2 += d2 * w
        g3 += d3 * w
        g4 += d4 * w
        a00 += d0 * d0
        a10 += d1 * d0
        a11 += d1 * d1
        a20 += d2 * d0
        a21 += d2 * d1
        a22 += d2 * d2
        a30 += d3 * d0
        a31 += d3 * d1
        a32 += d3 * d2
        a33 += d3 * d3
        a40 += d4 * d0
        a41 += d4 * d1
        a42 += d4 * d2
        a43 += d4 * d3
        a44 += d4 * d4
        if q > 0:
            r = Q[i, 0]
            qw0 += r * w
            q00 += r * d0
            q01 += r * d1
            q02 += r * d2
            q03 += r * d3
            q04 += r * d4
            if q > 1:
                r = Q[i, 1]
                qw1 += r * w
                q10 += r * d0
                q11 += r * d1
                q12 += r * d2
                q13 += r * d3
                q14 += r * d4
    Bw = np.array([g0, g1, g2, g3, g4])
    BB = np.array([[a00, a10, a20, a30, a40], [a10, a11, a21, a31, a41], [a20, a21, a22, a32, a42],
                   [a30, a31, a32, a33, a43], [a40, a41, a42, a43, a44]])
    Qw = np.array([qw0, qw1])[:q].copy()
    QB = np.array([[q00, q01, q02, q03, q04], [q10, q11, q12, q13, q14]])[:q].copy()
    return ww, Bw, BB, Qw, QB


@jit
def extra_sums(y, off, m, S, inv_sigma, phi, gain, Q):
    """The sums of ``basis_sums`` that involve the extra basis columns E = S[:, 4:] / sigma (a law's parameters
    beyond a, b, Dc and k, e.g. Nagata's c), prewhitened alike: (E'w (e,), E'B (e, 5), E'E (e, e), Q'E (q, e)),
    B the five columns of ``basis_sums``."""
    n = y.size
    e = S.shape[1] - 4
    q = Q.shape[1]
    Ew = np.zeros(e)
    EB = np.zeros((e, 5))
    EE = np.zeros((e, e))
    QE = np.zeros((q, e))
    c, cp, d = np.zeros(5), np.zeros(5), np.zeros(5)
    x, xp, g = np.zeros(e), np.zeros(e), np.zeros(e)
    zp = 0.0
    for i in range(n):
        s = inv_sigma[i]
        z = (off + m[i] - y[i]) * s
        for j in range(4):
            c[j] = S[i, j] * s
        c[4] = s
        for j in range(e):
            x[j] = S[i, 4 + j] * s
        f = phi[i]
        if f != 0.0:
            k = gain[i]
            w = (z - f * zp) * k
            for j in range(5):
                d[j] = (c[j] - f * cp[j]) * k
            for j in range(e):
                g[j] = (x[j] - f * xp[j]) * k
        else:
            w = z
            for j in range(5):
                d[j] = c[j]
            for j in range(e):
                g[j] = x[j]
        zp = z
        for j in range(5):  # element by element: slice assignments tripled the compile time
            cp[j] = c[j]
        for j in range(e):
            xp[j] = x[j]
        for j in range(e):
            Ew[j] += g[j] * w
            for l in range(5):
                EB[j, l] += g[j] * d[l]
            for l in range(e):
                EE[j, l] += g[j] * g[l]
            for r in range(q):
                QE[r, j] += Q[i, r] * g[j]
    return Ew, EB, EE, QE


def all_sums(y, off, m, S, inv_sigma, phi, gain, Q):
    """``basis_sums`` over the basis (S[:, :4], 1, S[:, 4:]) / sigma: the five columns of ``basis_sums``, then those
    of ``extra_sums`` where S has more than four columns."""
    sums = basis_sums(y, off, m, S, inv_sigma, phi, gain, Q)
    if S.shape[1] == 4:
        return sums
    ww, Bw, BB, Qw, QB = sums
    Ew, EB, EE, QE = extra_sums(y, off, m, S, inv_sigma, phi, gain, Q)
    return ww, np.concatenate([Bw, Ew]), np.block([[BB, EB.T], [EB, EE]]), Qw, np.hstack([QB, QE])


def compile_sums(extra: bool) -> None:
    """Compile ``basis_sums`` (and, with ``extra``, ``extra_sums``) here, or load them from numba's cache, with the
    one type signature the fit calls them with (three samples): a pool forked after this inherits them compiled."""
    n, ones = 3, np.ones(3)
    all_sums(ones, 0.0, ones, np.ones((n, 5 if extra else 4)), ones, np.full(n, 0.5), ones, np.ones((n, 1)))
