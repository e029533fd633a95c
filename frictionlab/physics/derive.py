"""Spin from rotation angle: cameras measure theta(t), not omega(t).

Two routes, both linear smoothers of theta, so the noise they pass on to omega is known:

* ``poly9``  -- the paper's route (Methods): a 9th-order least-squares polynomial of theta(t),
  differentiated. Its derivative swings near the ends of the record (Runge-like edge effects).
* ``spline`` -- a cubic smoothing spline whose roughness penalty is chosen by generalized
  cross-validation (scipy ``make_smoothing_spline``), differentiated.

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


def _spline_operators(t: np.ndarray, theta: np.ndarray):
    """Smoother S and derivative D of the cubic smoothing spline whose penalty minimizes GCV.

    The spline is linear in the data for a fixed penalty, so fitting the identity matrix
    gives S and D exactly; GCV(lam) = n |theta - S theta|^2 / (n - tr S)^2 on a log grid.
    """
    from scipy.interpolate import make_smoothing_spline

    n = t.size
    if n < 5:
        raise DatasetError(f"spline needs at least 5 theta samples, got {n}")
    eye = np.eye(n)
    best = None
    for lam in (t[-1] - t[0]) ** 3 * np.logspace(-14, 1, 61):
        spl = make_smoothing_spline(t, eye, lam=lam)
        S = spl(t)
        gcv = n * np.sum((theta - S @ theta) ** 2) / max(n - np.trace(S), 1e-9) ** 2
        if best is None or gcv < best[0]:
            best = (gcv, S, spl)
    _, S, spl = best
    return S, spl.derivative()(t)


def derive_omega(t: np.ndarray, theta: np.ndarray, method: str = "poly9", sigma_theta: float | None = None) -> Derived:
    """omega(t) [rad/s] from theta(t) [rad] by ``method`` (poly9 or spline).

    sigma_theta [rad] is the noise of theta; if None it is estimated from the smoother's
    residuals (degrees of freedom taken into account).
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
