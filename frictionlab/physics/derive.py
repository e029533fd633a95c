"""Spin from rotation angle: cameras measure theta(t), not omega(t).

Two routes, both linear smoothers of theta, so the noise they pass on to omega is known:

* ``poly9``  -- the paper's route (Methods): a 9th-order least-squares polynomial of theta(t),
  differentiated. Its derivative swings near the ends of the record (Runge-like edge effects).
* ``spline`` -- a cubic smoothing spline (the one scipy's ``make_smoothing_spline`` fits, here in
  closed form) whose roughness penalty is chosen by generalized cross-validation, differentiated.

``derive_omega(t, theta, method, sigma_theta)`` returns a ``Derived`` record: omega [rad/s],
its standard deviation per point [rad/s] (from sigma_theta through the smoother), and the
smoothed theta [rad]. Times in s, angles in rad.
"""
from __future__ import annotations

import attrs
import numpy as np

from ..core.errors import DatasetError

METHODS = {
    "poly9": "9th-order least-squares polynomial of theta(t), differentiated (the paper's Methods)",
    "spline": "cubic smoothing spline of theta(t), penalty chosen by generalized cross-validation, differentiated",
}


@attrs.frozen(eq=False)
class Derived:
    """omega derived from theta: values and 1-sigma per point [rad/s], smoothed theta [rad]."""

    method: str
    t: np.ndarray
    omega: np.ndarray
    sigma: np.ndarray
    theta_fit: np.ndarray
    description: str


def _poly9_operators(t: np.ndarray):
    """Matrices S (theta -> smoothed theta) and D (theta -> d theta/dt) of the degree-9 fit."""
    n = t.size
    if n < 11:
        raise DatasetError(f"poly9 needs at least 11 theta samples, got {n}")
    lo, hi = t[0], t[-1]
    x = (2 * t - (lo + hi)) / (hi - lo)  # [-1, 1]: well conditioned Legendre basis
    V = np.polynomial.legendre.legvander(x, 9)
    dV = np.zeros_like(V)
    for k in range(10):
        c = np.zeros(10)
        c[k] = 1.0
        dV[:, k] = np.polynomial.legendre.legval(x, np.polynomial.legendre.legder(c)) * 2 / (hi - lo)
    pinv = np.linalg.pinv(V)
    return V @ pinv, dV @ pinv


def _gcv_spline(t: np.ndarray, theta: np.ndarray, lams: np.ndarray):
    """(lam, S, D) of the cubic smoothing spline whose penalty, among lams [s^3], minimizes GCV.

    The spline minimizes |theta - f(t)|^2 + lam * integral f''^2 dt (as scipy's
    ``make_smoothing_spline``): a natural cubic spline whose values at t are S theta,
    S = (I + lam K)^-1 with K = Q R^-1 Q^T (Reinsch form: Q [1/s] takes second divided
    differences, R [s] is tridiagonal). K = U diag(d) U^T once (its two null directions, the
    straight lines, left out), so with the filter factors w = lam d / (1 + lam d),
    S = I - U diag(w) U^T, n - tr S = sum w and |theta - S theta| = |w U^T theta|: GCV(lam) =
    n |theta - S theta|^2 / (n - tr S)^2 costs O(n) per penalty. D [1/s] is the derivative at
    t of the natural spline through S's columns.
    """
    from scipy.linalg import cholesky_banded, solve_banded, solveh_banded, svd

    n = t.size
    h = np.diff(t)
    j = np.arange(n - 2)
    Q = np.zeros((n, n - 2))
    Q[j, j], Q[j + 1, j], Q[j + 2, j] = 1 / h[:-1], -1 / h[:-1] - 1 / h[1:], 1 / h[1:]
    R = np.array([np.r_[0.0, h[1:-1] / 6], (h[:-1] + h[1:]) / 3])  # upper band storage
    C = cholesky_banded(R)  # R = C^T C, C upper bidiagonal
    # K = B B^T with B = Q C^-1: B's singular values keep the smallest d accurate (the
    # gesvd driver: gesdd wakes the BLAS threads, costly on a busy machine at this size)
    Bt = solve_banded((1, 0), np.array([C[1], np.r_[C[0, 1:], 0.0]]), Q.T)
    U, s, _ = svd(Bt.T, full_matrices=False, lapack_driver="gesvd")
    w = np.outer(lams, s**2) / (1 + np.outer(lams, s**2))
    gcv = n * np.sum((w * (U.T @ theta)) ** 2, axis=1) / np.maximum(np.sum(w, axis=1), 1e-9) ** 2
    best = np.argmin(gcv)
    S = np.eye(n) - (U * w[best]) @ U.T
    # the spline through values g has second derivatives gamma = [0, R^-1 Q^T g, 0] at t, and
    # slopes (g[i+1] - g[i]) / h[i] - h[i] (2 gamma[i] + gamma[i+1]) / 6, at the last knot
    # (g[-1] - g[-2]) / h[-1] + h[-1] gamma[-2] / 6
    gamma = np.zeros((n, n))
    gamma[1:-1] = solveh_banded(R, Q.T @ S)
    D = np.empty((n, n))
    D[:-1] = (S[1:] - S[:-1]) / h[:, None] - h[:, None] * (2 * gamma[:-1] + gamma[1:]) / 6
    D[-1] = (S[-1] - S[-2]) / h[-1] + h[-1] * gamma[-2] / 6
    return lams[best], S, D


def _spline_operators(t: np.ndarray, theta: np.ndarray):
    """Smoother S and derivative D [1/s] of the cubic smoothing spline whose penalty minimizes GCV.

    The penalty [s^3] is chosen among (t[-1] - t[0])^3 * 10^k, k = -14 ... 1 in 60 equal log steps.
    """
    n = t.size
    if n < 5:
        raise DatasetError(f"spline needs at least 5 theta samples, got {n}")
    if np.any(np.diff(t) <= 0):
        raise DatasetError("spline needs strictly increasing times t")
    _, S, D = _gcv_spline(t, theta, (t[-1] - t[0]) ** 3 * np.logspace(-14, 1, 61))
    return S, D


def derive_omega(t: np.ndarray, theta: np.ndarray, method: str = "poly9", sigma_theta: float | None = None) -> Derived:
    """The spin omega(t) derived from a rotation-angle series theta(t), with its uncertainty.

    Parameters
    ----------
    t : array_like
        Sample times [s], increasing.
    theta : array_like
        Rotation angle [rad] at ``t``.
    method : {"poly9", "spline"}, default "poly9"
        A 9th-order polynomial (the paper's method) or a smoothing spline whose penalty is chosen by
        generalized cross-validation, differentiated.
    sigma_theta : float, optional
        The noise of theta [rad]; None estimates it from the smoother's residuals (their degrees of freedom
        taken into account).

    Returns
    -------
    Derived
        ``omega`` [rad/s] at ``t`` with its standard error, and how it was derived.

    Raises
    ------
    DatasetError
        An unknown method, or a series too short or not increasing in time for it.

    Examples
    --------
    >>> import numpy as np
    >>> import frictionlab as fl
    >>> t = np.linspace(0.0, 5e-4, 51)
    >>> d = fl.derive_omega(t, 700.0 * t, sigma_theta=1e-4)   # a steady 700 rad/s
    >>> bool(np.allclose(d.omega, 700.0, rtol=1e-3))
    True
    """
    if method not in METHODS:
        raise DatasetError(f"unknown omega derivation {method!r}; choose one of {', '.join(METHODS)}")
    t = np.asarray(t, dtype=float)
    theta = np.asarray(theta, dtype=float)
    if t.shape != theta.shape or t.ndim != 1:
        raise DatasetError("derive_omega: t and theta must be 1-D arrays of equal length")
    S, D = _poly9_operators(t) if method == "poly9" else _spline_operators(t, theta)
    theta_fit = S @ theta
    if sigma_theta is None:
        dof = max(t.size - np.trace(S), 1.0)
        sigma_theta = float(np.sqrt(np.sum((theta - theta_fit) ** 2) / dof))
    sigma = sigma_theta * np.sqrt(np.sum(D**2, axis=1))
    return Derived(method=method, t=t, omega=D @ theta, sigma=np.maximum(sigma, np.finfo(float).tiny),
                   theta_fit=theta_fit, description=METHODS[method])
