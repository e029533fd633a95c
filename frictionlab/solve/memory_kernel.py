"""The numba kernel of ``frictionlab.solve.memoryrhs`` (imported only when a solve uses it; needs numba).

``rhs`` and ``jac`` are the scaled right-hand side dz/ds and its Jacobian of one sliding phase of a built-in law
with memory (``memoryrhs`` says which laws and scenes, and what the arguments hold). Module-level functions,
so numba's on-disk cache (``cache=True``) serves later processes.
"""
import math

import numba
import numpy as np

from .memory_codes import (BAD, CALLS, COUPLED, DAHL, DAHL_SLID, DIRECTION, DRIVE, IL, ILOAD, INERTIA, ITH, IW, LAW,
                           LUGRE, MASS, MAXCALLS, NORMAL, NORMAL_HALF_SINE, NORMAL_PHI, NORMAL_TC, NORMAL_VALUE,
                           NOT_FINITE, RADIUS, RS_PRZ, RS_SLIP, S0, SENSE, SPIN, STRICT, STIFFNESS, STOP_T, TINY, TOO_MANY, TSCALE,
                           TURNED, V0)

jit = numba.njit(cache=True, fastmath=False, error_model="numpy")


@jit
def _sign(x):
    return 1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)


@jit
def dahl_slid(P, s0, X):
    """Dahl's s = 1 - mu_d sign(u)/mu_c and ds/dX after a slip X [m] in one sense from s0: ds/dX = -(sigma/mu_c)
    |s|^alpha sign(s) solved in closed form (for alpha < 1, s reaches 0 after a finite slip and stays)."""
    mu_c, sigma, alpha = P[0], P[1], P[2]
    k = sigma / mu_c
    if s0 == 0.0:
        return 0.0, 0.0
    if alpha == 1.0:
        s = s0 * math.exp(-k * X)
        return s, -k * s
    base = abs(s0) ** (1.0 - alpha) + (alpha - 1.0) * k * X
    if base <= 0.0:  # alpha < 1: arrived
        return 0.0, 0.0
    s = _sign(s0) * base ** (1.0 / (1.0 - alpha))
    return s, -k * abs(s) ** alpha * _sign(s0)


@jit
def law(code, P, C, u, x):
    """(mu, d mu/du, d mu/dx, rate, d rate/du, d rate/dx) of the law ``code`` per unit normal force at slip u
    [m/s] and state x, parameters P in the law's order (laws/lugre.py, dahl.py, rate_state*.py; RS_PRZ: the PRZ law). DAHL_SLID is
    Dahl with the slip X [m] since the phase began as its state (x), while the slip keeps the sense C[SENSE]:
    mu_d = sense mu_c (1 - s(X)) from s(0) = C[S0] (``dahl_slid``), dX/dt = |u|: smooth where d mu_d/dt =
    sigma u |s|^alpha sign(s) is not (alpha < 1 at s = 0). Where the slip turns, ``rhs`` stops with C[BAD] =
    TURNED when C[STRICT]; otherwise it goes on with dX/dt = sense u (a stage past the turn, which an event ends)."""
    if code == DAHL_SLID:
        sense = C[SENSE]
        s, ds = dahl_slid(P, C[S0], x)
        return sense * P[0] * (1.0 - s), 0.0, -sense * P[0] * ds, u * sense, sense, 0.0
    if code == LUGRE:
        mu_c, mu_s, vs, s0, s1, s2 = P[0], P[1], P[2], P[3], P[4], P[5]
        q = u / vs
        e = math.exp(-(q * q))
        g = mu_c + (mu_s - mu_c) * e
        au = abs(u)
        zd = u - s0 * au * x / g
        dg = (mu_s - mu_c) * e * (-2.0 * q / vs)
        dzd_du = 1.0 - s0 * x * (_sign(u) * g - au * dg) / (g * g)
        dzd_dz = -s0 * au / g
        return s0 * x + s1 * zd + s2 * u, s1 * dzd_du + s2, s0 + s1 * dzd_dz, zd, dzd_du, dzd_dz
    if code == DAHL:
        mu_c, sigma, alpha = P[0], P[1], P[2]
        su = _sign(u)
        s = 1.0 - x * su / mu_c
        a = abs(s)
        pw = a**alpha
        rate = sigma * u * pw * _sign(s)
        # alpha |s|^(alpha - 1) is infinite at s = 0 for alpha < 1, where the rate itself is 0: held finite there
        slope = alpha * a ** (alpha - 1.0) if a > 0.0 else (alpha if alpha >= 1.0 else 0.0)
        return x, 0.0, 1.0, rate, sigma * pw * _sign(s), -sigma * abs(u) * slope / mu_c
    mu0, a, b, Dc = P[0], P[1], P[2], P[3]
    if code == RS_PRZ:  # PRZ reads theta / (2 Dc) where the others read theta / Dc
        Dc = 2.0 * Dc
    th = max(x, 1e-300)
    psi = mu0 + b * math.log(V0 * th / Dc)
    au = abs(u)
    su = _sign(u)
    if au > 0.0:
        L = math.log(au / (2.0 * V0)) + psi / a
        if L > 0:
            A = L + math.log1p(math.sqrt(1.0 + math.exp(-2.0 * L)))
            dA = 1.0 / math.sqrt(1.0 + math.exp(-2.0 * L))  # d asinh(e^L) / dL
        else:
            eL = math.exp(L)
            A = math.asinh(eL)
            dA = eL / math.sqrt(1.0 + eL * eL)
        mu = a * su * A
        dmu_du = a * dA / au
    else:
        mu, dA = 0.0, 0.0
        dmu_du = a * math.exp(min(psi / a, 700.0)) / (2.0 * V0)
    dmu_dth = b * su * dA / th if x > 1e-300 else 0.0
    r = au * x / Dc
    if code == RS_SLIP:
        if r > 0.0:
            lg = math.log(r)
            d = -(lg + 1.0)
            return mu, dmu_du, dmu_dth, -r * lg, d * su * x / Dc, d * au / Dc
        return mu, dmu_du, dmu_dth, 0.0, 0.0, 0.0
    if code == RS_PRZ:
        return mu, dmu_du, dmu_dth, 1.0 - r * r, -2.0 * r * su * x / Dc, -2.0 * r * au / Dc
    return mu, dmu_du, dmu_dth, 1.0 - r, -su * x / Dc, -au / Dc


@jit
def _normal(C, t):
    if C[NORMAL] == NORMAL_HALF_SINE:
        return C[NORMAL_VALUE] * math.sin(C[NORMAL_PHI] * t) if 0.0 <= t <= C[NORMAL_TC] else 0.0
    return C[NORMAL_VALUE]


@jit
def _velocity(V, t):
    """Load-point velocity at t [s] from V = (times, velocities) (``SpringLoad.velocity``)."""
    i = np.searchsorted(V[0], t, side="right") - 1
    return V[1, min(max(i, 0), V.shape[1] - 1)]


@jit
def _slip(C, y):
    u = y[0] - C[RADIUS] * y[int(C[IW])] if C[COUPLED] else y[0]
    d = C[DIRECTION]
    if d != 0.0 and not d * u > 0:
        return C[TINY], False
    return u, True


@jit
def _point(s, z, C, scale):
    """(t, unscaled states y, slip u, whether it slides, the law state's index, normal force N) at scaled (s, z)."""
    t = s * C[TSCALE]
    y = z * scale
    u, free = _slip(C, y)
    return t, y, u, free, int(C[IL]), _normal(C, t)


@jit
def rhs(s, z, P, C, scale, V):
    """dz/ds of the scaled phase (time s = t / TSCALE, states z = y / scale) at one state vector; counts calls in
    C[CALLS]: past C[MAXCALLS], where a value is not finite, or where a strict slid phase's slip turns, sets C[BAD]
    and raises FloatingPointError, which stops the solver at once (ODEPACK steps on through NaN, accepting steps
    whose error it cannot measure, to the end of the span)."""
    n = z.size
    out = np.empty(n)
    C[CALLS] += 1.0
    if C[CALLS] > C[MAXCALLS]:
        if C[BAD] != TOO_MANY:
            C[STOP_T] = s * C[TSCALE]
        C[BAD] = TOO_MANY
        raise FloatingPointError("stopped: see C[BAD]")
    tsc = C[TSCALE]
    t, y, u, free, il, N = _point(s, z, C, scale)
    code = int(C[LAW])
    if code == DAHL_SLID and C[STRICT] and u * C[SENSE] < 0.0:
        C[BAD] = TURNED
        raise FloatingPointError("stopped: see C[BAD]")
    mu, _, _, rate, _, _ = law(code, P, C, u, y[il])
    F = N * mu
    if not (math.isfinite(F) and math.isfinite(rate)):
        if C[BAD] == 0.0:
            C[BAD] = NOT_FINITE
        raise FloatingPointError("stopped: see C[BAD]")
    iload = int(C[ILOAD])
    if iload >= 0:
        out[0] = (N * y[iload] - F) / C[MASS]
        out[iload] = C[STIFFNESS] * (_velocity(V, t) - y[0])
    else:
        out[0] = C[DRIVE] - F / C[MASS]
    if C[SPIN]:
        iw = int(C[IW])
        out[iw] = F * C[RADIUS] / C[INERTIA]
        out[int(C[ITH])] = y[iw]
    out[il] = rate
    for i in range(n):
        out[i] = out[i] * tsc / scale[i]
    return out


@jit
def jac(s, z, P, C, scale, V):
    """d(dz/ds)/dz of ``rhs`` in closed form."""
    n = z.size
    J = np.zeros((n, n))
    tsc = C[TSCALE]
    _, y, u, free, il, N = _point(s, z, C, scale)
    _, dmu_du, dmu_dl, _, dr_du, dr_dl = law(int(C[LAW]), P, C, u, y[il])
    du = np.zeros(n)  # d u / d y
    iw = int(C[IW])
    if free:
        du[0] = 1.0
        if C[COUPLED]:
            du[iw] = -C[RADIUS]
    dF = N * dmu_du * du
    dF[il] += N * dmu_dl
    for j in range(n):
        J[0, j] = -dF[j] / C[MASS]
        J[il, j] = dr_du * du[j]
    J[il, il] += dr_dl
    iload = int(C[ILOAD])
    if iload >= 0:
        J[0, iload] += N / C[MASS]
        J[iload, 0] = -C[STIFFNESS]
    if C[SPIN]:
        for j in range(n):
            J[iw, j] = dF[j] * C[RADIUS] / C[INERTIA]
        J[int(C[ITH]), iw] = 1.0
    for i in range(n):
        for j in range(n):
            J[i, j] = J[i, j] * (tsc * scale[j] / scale[i])
    return J


@jit
def dahl_mu(P, s0, sense, X):
    """mu_d [-] after the slips X [m] (an array) of a DAHL_SLID phase (see ``law``)."""
    out = np.empty(X.size)
    for i in range(X.size):
        out[i] = sense * P[0] * (1.0 - dahl_slid(P, s0, X[i])[0])
    return out
