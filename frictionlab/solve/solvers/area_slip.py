"""Closed forms of F = k A u (the wear and Couette laws' family), used by ``exact``.

Half-sine area, no drive (the paper's impact, eq (6)): u = u0 exp(-b (1 - cos phi t)), whose integral is the
Bessel series ``bessel_integral`` (a Laplace-type series for large b). Constant or growing area with a constant
drive (the incline): slip relaxes, u' = g - lam u, in closed form with its stop (``relax_stop``).
Units: SI throughout (t [s], phi [1/s], lam [1/s], slip [m/s]).
"""
from __future__ import annotations

import math

import numpy as np
from scipy.special import ive

from ...core.errors import SolverError
from ...physics.scene import ConstantArea, GrowthArea, WeightNormal

B_LAPLACE = 500.0  # above this b the integral of exp(-2 b sin^2) is summed as a Laplace-type series


def bessel_integral(b, phi, t) -> np.ndarray:
    """int_0^t exp(b cos(phi s) - b) ds for 0 <= t <= pi/phi, to machine precision.

    b [-], phi [1/s] and t [s] broadcast against each other (a batch passes (n, 1) columns
    and an (n, m) grid).
    b <= 500: the Bessel (Jacobi-Anger) series ive(0,b) t + 2 sum_k ive(k,b) sin(k phi t) / (k phi);
    the sines come from the recurrence sin((k+1)x) = 2 cos(x) sin(kx) - sin((k-1)x); terms stop
    once 2 I_k(b) e^-b / k falls below 1e-17 I_0(b) e^-b for every b.
    b > 500: the series would need ~sqrt(90 b) terms (6e6 at b = 4.5e11) and loses accuracy;
    instead see ``_laplace_integral``.
    """
    b, phi, t = (np.asarray(v, dtype=float) for v in (b, phi, t))
    big = b > B_LAPLACE
    if not big.any():
        return _bessel_series(b, phi, t)
    if big.all():
        return _laplace_integral(b, phi, t)
    return np.where(big, _laplace_integral(np.where(big, b, 2 * B_LAPLACE), phi, t),
                    _bessel_series(np.where(big, 0.0, b), phi, t))


def _bessel_series(b, phi, t):
    kmax = int(math.ceil(math.sqrt(2.0 * max(float(np.max(b, initial=0.0)), 1.0) * 45.0))) + 20
    # every weight in one call; the series stops at the first k whose term is negligible for every b
    k = np.arange(kmax + 1, dtype=float).reshape((-1,) + (1,) * np.ndim(b))
    w = ive(k, b)
    small = (2.0 * w[1:] <= 1e-17 * k[1:] * w[0]).reshape(kmax, -1).all(axis=1)
    last = int(np.argmax(small)) + 1 if small.any() else kmax
    coef = 2.0 * w[1:] / (k[1:] * phi)
    x = phi * t
    out = w[0] * t
    out = out if out.shape == x.shape else np.broadcast_to(out, x.shape).copy()
    two_cos = np.cos(x)
    two_cos *= 2.0
    s_prev, s_k, tmp = np.zeros_like(x), np.sin(x), np.empty_like(x)
    for j in range(last):  # in place: the grid's arrays are the memory traffic, the same numbers as plainly
        np.multiply(coef[j], s_k, out=tmp)
        out += tmp
        if j + 1 < last:  # s_prev becomes sin((k+1)x)
            np.multiply(two_cos, s_k, out=tmp)
            np.subtract(tmp, s_prev, out=s_prev)
            s_prev, s_k = s_k, s_prev
    return out


def _laplace_integral(b, phi, t):
    """The same integral for large b: with x = sin(phi s / 2) it is (2/phi) int_0^X exp(-2 b x^2) / sqrt(1 - x^2) dx.

    The integrand is below exp(-b/2) for x > 1/2, so X is capped there and 1/sqrt(1 - x^2) is
    expanded, sum_n C(2n,n)/4^n x^(2n); each term is an incomplete gamma function and the terms
    fall like (1/(4b))^n.
    """
    from scipy.special import gamma, gammainc

    X = np.minimum(np.sin(phi * t / 2.0), 0.5)
    z = 2.0 * b * X * X
    out = np.zeros(np.broadcast(b, z).shape)
    c = 1.0
    for n in range(12):
        a = n + 0.5
        out = out + c * 0.5 * (2.0 * b) ** (-a) * gamma(a) * gammainc(a, z)
        c *= (2 * n + 1) / (2 * n + 2)
    return (2.0 / phi) * out
    return out


def _area_slip(plan, k, t0, y0, t):
    s = plan.scene
    u0 = plan.rigid_slip(y0)
    kappa = plan.kappa
    if isinstance(s.area, ConstantArea):
        return _relaxing(plan, u0, plan.drive, kappa * k * s.area.area, t - t0)
    if t0 != 0.0:
        raise SolverError("exact: the half-sine closed form starts at first contact only")
    tc = s.area.contact_time
    phi = math.pi / tc
    b = kappa * k * s.area.peak / phi
    tau = np.minimum(t, tc)
    u = u0 * np.exp(-2.0 * b * np.sin(phi * tau / 2.0) ** 2)
    int_u = u0 * bessel_integral(b, phi, tau)
    u_end = u0 * np.exp(-2.0 * b)
    int_u = int_u + u_end * np.maximum(t - tc, 0.0)
    J = (u0 - u) / kappa
    K = (u0 * t - int_u) / kappa
    return J, K


def _relax(u0, b, lam, dt):
    """u and int_0^dt u [m/s, m] of u' = b - lam u from u(0) = u0, for either sign of lam [1/s] (x = lam dt -> 0:
    the straight line): u = u0 exp(-x) + b dt g1, int u = u0 dt g1 + b dt^2 g2 with g1 = (1 - exp(-x)) / x and
    g2 = (x - 1 + exp(-x)) / x^2, written to stay exact for tiny |x|. Elementwise (a batch's columns)."""
    x = lam * dt
    ax = np.abs(x)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        g1 = np.where(ax > 1e-8, -np.expm1(-x) / np.where(x != 0, x, 1.0), 1.0 - x / 2.0 + x * x / 6.0)
        g2 = np.where(ax > 1e-5, (x + np.expm1(-x)) / np.where(x != 0, x * x, 1.0), 0.5 - x / 6.0 + x * x / 24.0)
        u = u0 * np.exp(-x) + b * dt * g1
    int_u = u0 * dt * g1 + b * dt * dt * g2
    return u, int_u


def _relaxing(plan, u0, b, lam, dt):
    """Impulse J and its integral K [N s, N s^2] over dt [s] of a phase whose slip relaxes, u' = b - lam u."""
    u, int_u = _relax(u0, b, lam, dt)
    a, kappa = plan.drive, plan.kappa
    return (a * dt - (u - u0)) / kappa, (a * dt * dt / 2.0 - (int_u - u0 * dt)) / kappa


def growth_slip(plan, form, sgn, u_s):
    """(sgn slip at the phase's start, b = sgn u' at zero slip [m/s^2], lam [1/s]) when sgn slip relaxes as
    g' = b - lam g: F = s (a N + c rate |u|) on a growth area under a weight (constant) normal force, with an
    area term (c != 0 somewhere); else None. Arrays broadcast (a batch's columns)."""
    s = plan.scene
    if not isinstance(s.area, GrowthArea) or not isinstance(s.normal, WeightNormal) or not np.any(np.asarray(form.c)):
        return None
    return sgn * u_s, sgn * plan.drive - plan.kappa * form.a * s.normal.value, plan.kappa * form.c * s.area.rate


def _time_to_zero(g0, b, lam):
    """Time [s] for g' = b - lam g to fall from g0 >= 0 to zero, inf where it never does: only with b < 0, and
    with lam < 0 only below the unstable rest g = b / lam. dt = log1p(z) / lam, z = -g0 lam / b, written
    (g0 / -b) log1p(z) / z to stay exact as lam -> 0 (the straight line, g0 / -b). Arrays broadcast."""
    g0, b, lam = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (g0, b, lam)))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        z = -g0 * lam / b
        h = np.where(np.abs(z) > 1e-8, np.log1p(np.maximum(z, -1.0)) / np.where(z != 0, z, 1.0),
                     1.0 - z / 2.0 + z * z / 3.0)
        dt = np.maximum(g0, 0.0) / -b * h
    return np.where((b < 0.0) & (z > -1.0), dt, np.inf)


def relax_stop(g0, b, lam, t0, T, margin):
    """Stop [s] of sgn slip g (``growth_slip``) from g0 at t0 by the rule of the scan (as ``_line_stop``): g must pass
    -margin by T; the stop is its zero when it started ahead (g0 > 0), else the time it passed; inf where not by T.
    g + margin obeys the same equation with b + lam margin. Arrays broadcast (a batch)."""
    passed = t0 + _time_to_zero(g0 + margin, b + lam * margin, lam)
    stop = np.where(g0 > 0.0, t0 + _time_to_zero(g0, b, lam), passed)
    return np.where(passed <= T, stop, np.inf)
