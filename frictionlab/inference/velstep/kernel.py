"""The velocity-step fit's inner sums, compiled (numba where it imports; ``core.jit``).

One pass over the samples of a dataset gives what Levenberg-Marquardt needs of the weighted, prewhitened
residual w and of five basis columns B (the four sensitivities dm/d(a, b, Dc, k) and a constant, and a sixth for a
law's extra parameter such as Nagata's c, each weighted and prewhitened), without forming them: w'w, B'w, B'B, and their parts along the orthonormal columns Q of the linear
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
    columns (S[:, 0], ..., S[:, 3], 1, then S[:, 4] where S has a fifth column: a law's extra parameter, Nagata's c)
    / sigma, each prewhitened as w_i = (z_i - phi_i z_{i-1}) gain_i with gain_i = 1 / sqrt(1 - phi_i^2) (read only
    where phi_i != 0). Q: n x q orthonormal columns of the linear parameters, q <= 2 (the steady-state friction and
    the trend with slip). Returns (w'w, B'w (nb,), B'B (nb, nb), Q'w (q,), Q'B (q, nb)), nb = 5 or 6."""
    n = y.size
    q = Q.shape[1]
    extra = S.shape[1] > 4
    ww = 0.0
    g0 = g1 = g2 = g3 = g4 = g5 = 0.0
    a00 = a10 = a11 = a20 = a21 = a22 = a30 = a31 = a32 = a33 = 0.0
    a40 = a41 = a42 = a43 = a44 = a50 = a51 = a52 = a53 = a54 = a55 = 0.0
    qw0 = q00 = q01 = q02 = q03 = q04 = q05 = 0.0
    qw1 = q10 = q11 = q12 = q13 = q14 = q15 = 0.0
    zp = p0 = p1 = p2 = p3 = p4 = p5 = 0.0
    for i in range(n):
        s = inv_sigma[i]
        z = (off + m[i] - y[i]) * s
        c0, c1, c2, c3, c4 = S[i, 0] * s, S[i, 1] * s, S[i, 2] * s, S[i, 3] * s, s
        c5 = S[i, 4] * s if extra else 0.0
        f = phi[i]
        if f != 0.0:
            k = gain[i]
            w = (z - f * zp) * k
            d0, d1, d2 = (c0 - f * p0) * k, (c1 - f * p1) * k, (c2 - f * p2) * k
            d3, d4, d5 = (c3 - f * p3) * k, (c4 - f * p4) * k, (c5 - f * p5) * k
        else:
            w, d0, d1, d2, d3, d4, d5 = z, c0, c1, c2, c3, c4, c5
        zp, p0, p1, p2, p3, p4, p5 = z, c0, c1, c2, c3, c4, c5
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
        if extra:
            g5 += d5 * w
            a50 += d5 * d0
            a51 += d5 * d1
            a52 += d5 * d2
            a53 += d5 * d3
            a54 += d5 * d4
            a55 += d5 * d5
        if q > 0:
            r = Q[i, 0]
            qw0 += r * w
            q00 += r * d0
            q01 += r * d1
            q02 += r * d2
            q03 += r * d3
            q04 += r * d4
            if extra:
                q05 += r * d5
            if q > 1:
                r = Q[i, 1]
                qw1 += r * w
                q10 += r * d0
                q11 += r * d1
                q12 += r * d2
                q13 += r * d3
                q14 += r * d4
                if extra:
                    q15 += r * d5
    nb = 6 if extra else 5
    Bw = np.array([g0, g1, g2, g3, g4, g5])[:nb].copy()
    BB = np.array([[a00, a10, a20, a30, a40, a50], [a10, a11, a21, a31, a41, a51], [a20, a21, a22, a32, a42, a52],
                   [a30, a31, a32, a33, a43, a53], [a40, a41, a42, a43, a44, a54],
                   [a50, a51, a52, a53, a54, a55]])[:nb, :nb].copy()
    Qw = np.array([qw0, qw1])[:q].copy()
    QB = np.array([[q00, q01, q02, q03, q04, q05], [q10, q11, q12, q13, q14, q15]])[:q, :nb].copy()
    return ww, Bw, BB, Qw, QB


def all_sums(y, off, m, S, inv_sigma, phi, gain, Q):
    """``basis_sums`` over the basis (S[:, :4], 1, S[:, 4:]) / sigma: S holds at most one extra column (the laws'
    ``quasistatic.EXTRA``)."""
    if S.shape[1] > 5:
        raise ValueError(f"velocity-step sums: {S.shape[1] - 4} extra sensitivity columns, at most 1 is summed")
    return basis_sums(y, off, m, S, inv_sigma, phi, gain, Q)


def compile_sums() -> None:
    """Compile ``basis_sums`` here, or load it from numba's cache, with the one type signature the fit calls it
    with (three samples): a pool forked after this inherits it compiled."""
    n, ones = 3, np.ones(3)
    all_sums(ones, 0.0, ones, np.ones((n, 5)), ones, np.full(n, 0.5), ones, np.ones((n, 1)))
