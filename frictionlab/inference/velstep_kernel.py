"""The velocity-step fit's inner sums, compiled (numba where it imports; ``core.jit``).

One pass over the samples of a dataset gives what Levenberg-Marquardt needs of the weighted, prewhitened
residual w and its Jacobian C by the free parameters, without forming C: w'w, C'w, C'C, and their parts along
the orthonormal columns Q of the linear parameters (Q'w, Q'C), from which the variable projection's
r'r = w'w - |Q'w|^2, J'r = C'w - (Q'C)'(Q'w) and J'J = C'C - (Q'C)'(Q'C) follow. Memory: nothing per sample.
"""
import math

import numpy as np

from ..core.jit import jit


@jit
def normal_equations(y, off, m, S, sigma, phi, idx, mult, const, Q):
    """Sums of one dataset (module docstring) for residual z = (off + m - y) / sigma and columns
    C_j = (S[:, idx_j] mult_j + const_j) / sigma (idx_j = -1: a zero column), each prewhitened,
    w_i = (z_i - phi_i z_{i-1}) / sqrt(1 - phi_i^2). Returns (w'w, C'w, C'C, Q'w, Q'C)."""
    n = y.size
    p = idx.size
    q = Q.shape[1]
    ww = 0.0
    Cw = np.zeros(p)
    CC = np.zeros((p, p))
    Qw = np.zeros(q)
    QC = np.zeros((q, p))
    c = np.zeros(p)
    c_prev = np.zeros(p)
    z_prev = 0.0
    for i in range(n):
        z = (off + m[i] - y[i]) / sigma[i]
        for j in range(p):
            c[j] = (S[i, idx[j]] * mult[j] + const[j]) / sigma[i] if idx[j] >= 0 else 0.0
        f = phi[i]
        if f != 0.0:
            scale = 1.0 / math.sqrt(1.0 - f * f)
            w = (z - f * z_prev) * scale
            z_prev = z
            for j in range(p):
                cj = (c[j] - f * c_prev[j]) * scale
                c_prev[j] = c[j]
                c[j] = cj
        else:
            w = z
            z_prev = z
            for j in range(p):
                c_prev[j] = c[j]
        ww += w * w
        for j in range(p):
            Cw[j] += c[j] * w
            for k in range(j + 1):
                CC[j, k] += c[j] * c[k]
        for r in range(q):
            Qw[r] += Q[i, r] * w
            for j in range(p):
                QC[r, j] += Q[i, r] * c[j]
    for j in range(p):
        for k in range(j):
            CC[k, j] = CC[j, k]
    return ww, Cw, CC, Qw, QC
