"""Long-run (HAC) covariance of a serially correlated series: Newey and West (1987), Bartlett window.

For rows s_t of a series (t = 1..n, columns the quantities), mean removed,

    S = Gamma_0 + sum_{j=1..L} (1 - j / (L + 1)) (Gamma_j + Gamma_j'),   Gamma_j = sum_t s_t s_{t-j}' / n,

positive semi-definite for any L; L = NW_LAGS(n) = floor(4 (n / 100)^(2/9)) by Newey and West's rule of thumb.
Used by Vuong's test (the long-run variance of pointwise log-likelihood differences) and by the sandwich error
bars of a fit whose noise no model whitens (``velstep.result``).
"""
from __future__ import annotations

import numpy as np


def nw_lags(n: int) -> int:
    """Newey-West's rule of thumb for the Bartlett window: floor(4 (n / 100)^(2/9))."""
    return int(4 * (n / 100.0) ** (2.0 / 9.0))


def long_run_covariance(s, lags: int | None = None, center: bool = True) -> np.ndarray:
    """The Newey-West long-run covariance (module docstring) of the rows of s (n x m, or a vector: 1 x 1), its
    mean removed when ``center``."""
    s = np.asarray(s, dtype=float)
    s = s[:, None] if s.ndim == 1 else s
    n = s.shape[0]
    L = nw_lags(n) if lags is None else int(lags)
    e = s - s.mean(axis=0) if center else s
    out = e.T @ e / n
    for j in range(1, min(L, n - 1) + 1):
        g = e[j:].T @ e[:-j] / n
        out += (1.0 - j / (L + 1.0)) * (g + g.T)
    return out
