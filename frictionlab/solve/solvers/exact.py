"""Closed-form solutions, for laws whose ``form`` is known and scenes that admit one.

AreaSlipForm, F = k A u (``area_slip``):
  half-sine area, no drive (the paper's impact, eq (6)):  u = u0 exp(-b (1 - cos phi t)),
      b = kappa k A0 / phi (kappa = 1/m, or 1/m + r^2/I with slip coupling); the integral of u
      is a Bessel series, int_0^t exp(b cos phi s - b) ds = ive(0,b) t + 2 sum_k ive(k,b) sin(k phi t)/(k phi).
  constant area, constant drive a (incline):  u = u_inf + (u0 - u_inf) exp(-t/tau),
      tau = 1/(kappa k A), u_inf = a tau.
NormalAreaRateForm, F = s (a N + c dA/dt) while slip keeps its sign s:
  u = u_s + drive (t - t_s) - kappa s [a (IN(t) - IN(t_s)) + c (A(t) - A(t_s))], IN = int N dt,
  for half-sine or constant (weight) N and half-sine or constant A; slip reaching zero is
  located by root finding and handed to the stick logic.
  growth area A = A0 + rate x (x the sliding length, dA/dt = rate |u|) and constant (weight) N, the
  incline: F = s a N + c rate u, so slip obeys a linear equation, u' = b - lam u with lam = kappa c rate
  [1/s] and b = drive - kappa s a N [m/s^2]:  u = u_s exp(-lam dt) + b dt (1 - exp(-lam dt)) / (lam dt)
  (lam < 0, eta' < 0, lets slip grow); the stop, where s u falls to zero, is in closed form too.
In every case the friction impulse J(t) = int F dt and its integral K(t) give the states:
  v = v_s + drive dt - J/m,  omega = omega_s + r J / I,  theta = theta_s + omega_s dt + r K / I,
  and the sliding length, where the plan carries it, x = x_s + s (u_s dt + drive dt^2 / 2 - kappa K).
"""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from ...core.errors import SolverError
from ...physics.law import AreaSlipForm, NormalAreaRateForm
from ...physics.scene import ConstantArea, GrowthArea, HalfSineArea, HalfSineNormal, WeightNormal
from .area_slip import _area_slip, _relaxing, growth_slip, relax_stop

SCAN = 4096  # grid points scanned for the first zero of slip
SLIP_MARGIN = 1e-12  # slip, relative to its scale, by which a stop must pass zero (as in ode.zero_slip)


def check(plan, p) -> None:
    """Raise SolverError unless a closed form exists for this law and scene."""
    _form_and_reason(plan, p)


def _form_and_reason(plan, p):
    law, s = plan.law, plan.scene
    name = f"law '{law.name}'"
    if law.states:
        raise SolverError(f"exact: {name} has internal state ({', '.join(law.state_names)}): closed forms do not "
                          "apply; use --solver ode")
    form = law.form(p)
    if form is None:
        raise SolverError(f"exact: {name} declares no closed form; use the ode solver")
    if "xi" in plan.states:
        raise SolverError("exact: no closed form with tangential compliance; use the ode solver")
    if isinstance(form, AreaSlipForm):
        if isinstance(s.area, HalfSineArea) and plan.drive == 0.0:
            return form
        if isinstance(s.area, ConstantArea):
            return form
        raise SolverError(f"exact: {name} has a closed form only with a half-sine area and no drive, "
                          f"or a constant area; this scene has {type(s.area).__name__} and drive {plan.drive:g} m/s^2")
    if isinstance(form, NormalAreaRateForm):
        if not isinstance(s.normal, (HalfSineNormal, WeightNormal)):
            raise SolverError(f"exact: {name} needs a half-sine or weight normal force; this scene has "
                              f"{type(s.normal).__name__}")
        if form.c != 0.0 and isinstance(s.area, GrowthArea):
            if not isinstance(s.normal, WeightNormal):
                raise SolverError(f"exact: {name} on a growth area needs a weight normal force (an incline); this "
                                  f"scene has {type(s.normal).__name__}")
            return form
        if form.c != 0.0 and not isinstance(s.area, (HalfSineArea, ConstantArea)):
            raise SolverError(f"exact: {name} needs a half-sine, constant or growth area; this scene has "
                              f"{type(s.area).__name__}")
        return form
    raise SolverError(f"exact: {name} returned an unknown form {form!r}")


def make_slide():
    def slide(plan, p, t0, y0, direction, t_out):
        form = _form_and_reason(plan, p)
        t_out = np.asarray(t_out, dtype=float)
        if isinstance(form, AreaSlipForm):
            (J, K), t_stop = _area_slip(plan, form.k, t0, y0, t_out), None
        else:
            J, K, t_stop = _normal_area_rate(plan, form, t0, y0, direction, t_out)
        keep = t_out <= t_stop if t_stop is not None else np.ones(t_out.shape, dtype=bool)
        Y = _states(plan, t0, y0, t_out[keep], J[keep], K[keep], direction=direction)
        y_stop = None
        if t_stop is not None:
            Js, Ks = _normal_area_rate(plan, form, t0, y0, direction, np.array([t_stop]), find_stop=False)[:2]
            y_stop = _states(plan, t0, y0, np.array([t_stop]), Js, Ks, direction=direction)[:, 0]
        return Y, t_stop, y_stop, {"nfev": 0}

    return slide


def _states(plan, t0, y0, t, J, K, out=None, direction=1.0):
    """States at times t from the friction impulse J and its integral K (terms that vanish skipped: a batch
    evaluates this on large grids); the sliding length x, where the plan carries it, grows by the integral of
    slip times the phase's slip ``direction`` (+1, -1; a column on a batch)."""
    s = plan.scene
    dt = t - t0
    if out is None:
        out = np.empty((len(plan.states),) + np.broadcast_shapes(np.shape(J), np.shape(dt)))
    for i, name in enumerate(plan.states):
        if name == "v":
            np.divide(J, -s.mass, out=out[i])
            out[i] += y0[i]
            if np.asarray(plan.drive).any():
                out[i] += plan.drive * dt
        elif name == "omega":
            np.multiply(J, s.radius / s.inertia, out=out[i])
            out[i] += y0[i]
        elif name == "theta":
            np.multiply(K, s.radius / s.inertia, out=out[i])
            out[i] += y0[i]
            w0 = y0[plan.index("omega")]
            if np.asarray(w0).any():
                out[i] += w0 * dt
        elif name == "x":  # int u = u_s dt + drive dt^2 / 2 - kappa K over the phase, of the phase's sign
            slid = plan.rigid_slip(y0) * dt + plan.drive * dt * dt / 2.0 - plan.kappa * K
            out[i] = y0[i] + np.where(np.asarray(direction) < 0, -1.0, 1.0) * slid
        else:  # pragma: no cover - guarded by check()
            raise SolverError(f"exact: state '{name}' has no closed form")
    return out


# --- F = s (a N + c dA/dt) --------------------------------------------------------------
def _normal_integrals(normal, t, a=1.0, second=True, trig=None):
    """a IN and a IIN: IN = int_0^t N, IIN = int_0^t IN, for half-sine or constant N (a: a factor per
    scene, folded into the coefficients; the term of times after contact skipped when there are none).
    second=False: (a IN, None), the same a IN for less work (a stop search reads the impulse only).
    trig: (cos x, sin x) of the half-sine's phase x at t (``_half_sine_trig``), when the caller has them."""
    t = np.asarray(t, dtype=float)
    if isinstance(normal, WeightNormal):
        return a * normal.value * t, (a * normal.value * t * t / 2.0 if second else None)
    tc = normal.contact_time
    phi = math.pi / tc
    c = a * normal.peak / phi
    after = bool(((t.max(axis=-1, keepdims=True) if t.ndim else t) > tc).any())  # each row's latest time
    tau = np.minimum(t, tc) if after else t
    if trig is not None:  # the same numbers as below, from the shared cos and sin
        cos_x, sin_x = trig
        IN = c * (1.0 - cos_x)
        IIN = c * (tau - sin_x / phi) if second else None
    else:
        x = phi * tau
        if not second:
            return c * (1.0 - np.cos(x)), None
        if x.ndim == 0 or np.broadcast_shapes(x.shape, np.shape(c)) != x.shape:  # small inputs: plainly
            IN, IIN = c * (1.0 - np.cos(x)), c * (tau - np.sin(x) / phi)
        else:  # large grids: in place, no temporaries
            IN = np.cos(x)
            np.subtract(1.0, IN, out=IN)
            IN *= c
            IIN = np.sin(x, out=x)
            IIN /= -phi
            IIN += tau
            IIN *= c
    if after and second:
        IIN = IIN + (2.0 * c) * np.maximum(t - tc, 0.0)
    return IN, IIN


def _half_sine_trig(tc, t) -> tuple[np.ndarray, np.ndarray]:
    """(cos x, sin x) with x = pi min(t, tc) / tc: what the integrals of a half-sine N and a half-sine A of the
    same contact time tc [s] both evaluate, computed once for the two."""
    x = (math.pi / tc) * np.minimum(t, tc)
    return np.cos(x), np.sin(x)


def _area_integrals(area, t, second=True, trig=None):
    """A(t) and int_0^t A, for half-sine or constant A (zeros without an area model); second=False: (A, None).
    trig: (cos x, sin x) of the half-sine's phase at t (``_half_sine_trig``), when the caller has them."""
    if area is None:
        return np.zeros_like(t), (np.zeros_like(t) if second else None)
    if isinstance(area, ConstantArea):
        return area.area + np.zeros_like(t), (area.area * t if second else None)  # a batch's areas: a column
    tc = area.contact_time
    phi = math.pi / tc
    if trig is not None:
        cos_x, sin_x = trig
        A = np.where(t <= tc, area.peak * sin_x, 0.0)
        return A, (area.peak / phi * (1.0 - cos_x) if second else None)
    tau = np.minimum(t, tc)
    A = np.where(t <= tc, area.peak * np.sin(phi * tau), 0.0)
    return A, (area.peak / phi * (1.0 - np.cos(phi * tau)) if second else None)


def form_branch(form) -> tuple[bool, bool]:
    """What the stop search decides from a NormalAreaRateForm for all its scenes at once (arrays on a batch): no
    area term anywhere (c = 0), and a >= 0 everywhere. Scenes batched only with others of the same branch get,
    bit for bit, the answer of their own batch; every other step runs row by row. (True, True) for any other
    form (F = k A u has no stop search)."""
    c, a = getattr(form, "c", 0.0), getattr(form, "a", 0.0)
    return bool((np.asarray(c) == 0.0).all()), bool((np.asarray(a) >= 0.0).all())


def closed_stop_applies(plan, form, t0) -> bool:
    """Whether ``half_sine_stop`` gives the stop: F = s a N (a >= 0, no area term), N a half-sine
    pulse, no drive, from first contact (Coulomb on an impact)."""
    return bool((np.asarray(t0) == 0.0).all() and form_branch(form) == (True, True)
                and isinstance(plan.scene.normal, HalfSineNormal) and (np.asarray(plan.drive) == 0.0).all())


def half_sine_stop(plan, form, u_s):
    """Time [s] at which slip u_s reaches zero under F = s a N, N = Np sin(phi t) (see
    ``closed_stop_applies``): kappa a IN(t) = |u_s| with IN = (2 Np / phi) sin^2(phi t / 2), so
    t = (2 / phi) arcsin(sqrt(q / 2)), q = |u_s| phi / (kappa a Np) (the half-angle form keeps early
    stops accurate); inf where q > 2 (the pulse ends first). Arrays broadcast (a batch)."""
    n = plan.scene.normal
    phi = np.pi / np.asarray(n.contact_time, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        q = np.abs(u_s) * phi / (plan.kappa * form.a * n.peak)
        return np.where(q <= 2.0, 2.0 / phi * np.arcsin(np.sqrt(np.minimum(q, 2.0) / 2.0)), np.inf)


# --- where slip reaches zero, in closed form where it has one --------------------------
def _linear_slip(plan, form, sgn, u_s):
    """(sgn slip at the phase's start, its rate) when slip is linear in time: a weight normal force and no area
    term (none, or a constant area), as on an incline; else None."""
    s = plan.scene
    if not isinstance(s.normal, WeightNormal) or not (form.c == 0.0 or isinstance(s.area, ConstantArea)):
        return None
    return sgn * u_s, sgn * plan.drive - plan.kappa * form.a * s.normal.value


def _line_stop(g0, rate, t0, T, margin):
    """Stop of slip g0 + rate (t - t0) [s] by the rule of the scan: it must pass zero by ``margin``; the stop is its
    zero when it started ahead (g0 > 0), else the time it passed; None if not by T."""
    if not rate < 0.0:
        return None
    passed = t0 + (margin + g0) / -rate
    if passed > T:
        return None
    return t0 + g0 / -rate if g0 > 0.0 else passed


def _pulse_slip(plan, form, sgn, u_s):
    """From first contact, sliding (sgn slip > 0), with half-sine N and A (or none) of one contact time and no
    drive, sgn slip is C0 + B cos(phi t) + S sin(phi t): (C0, B, S, phi); else None. Works on a batch's columns
    (the batch engine solves rows that start without slip one by one)."""
    s = plan.scene
    area = s.area if np.any(np.asarray(form.c) != 0.0) else None
    if (not isinstance(s.normal, HalfSineNormal) or np.any(np.asarray(plan.drive) != 0.0)
            or not (area is None or (isinstance(area, HalfSineArea)
                                     and np.all(np.asarray(area.contact_time) == s.normal.contact_time)))):
        return None
    phi = math.pi / s.normal.contact_time
    B = plan.kappa * form.a * s.normal.peak / phi
    S = -plan.kappa * form.c * area.peak if area is not None else 0.0
    return sgn * u_s - B, B, S, phi


def pulse_stop(C0, B, S, phi, t_end, margin):
    """First stop [s] of slip g = C0 + B cos(phi t) + S sin(phi t) = C0 + R cos(phi t - delta) after t = 0, where
    g(0) > 0 (``_pulse_slip``): where g, falling, passes -margin by t_end, its zero on that falling arc; inf where it
    does not. g falls on the arcs phi t = delta + arccos(level) (+ 2 pi), one per period, so the first arc after 0
    is the one. Arrays broadcast (a batch)."""
    R = np.hypot(B, S)
    delta = np.arctan2(S, B)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # R tiny: level +-inf, handled below
        level, zero = (-margin - C0) / R, -C0 / R
    a_level, a_zero = np.arccos(np.clip(level, -1.0, 1.0)), np.arccos(np.clip(zero, -1.0, 1.0))
    x_pass = delta + a_level
    x_pass = np.where(x_pass > 0.0, x_pass, x_pass + 2.0 * math.pi)
    passes = (R > 0.0) & (level >= -1.0) & (x_pass <= phi * t_end)
    return np.where(passes, (x_pass - (a_level - a_zero)) / phi, np.inf)


def _slip_margin(plan, T: float) -> float:
    """SLIP_MARGIN of the slip's scale over a phase ending at T [s]: the initial slip, the drive's, the spin's."""
    s = plan.scene
    return SLIP_MARGIN * max(abs(s.u0), abs(plan.drive) * T, abs(s.omega0) * (s.radius or 0.0), 1e-300)


def _normal_area_rate(plan, form, t0, y0, direction, t, find_stop=True):
    """Friction impulse J and its integral K from t0 at times t (and, with find_stop, the stop).

    t0 and direction are floats, or (with find_stop=False) per-scene columns (k, 1) of a batch
    broadcasting against t (k, q): a batch restarts its scenes' sliding phases at their own times."""
    s = plan.scene
    sgn = np.where(np.asarray(direction) != 0, direction, 1.0)
    u_s = plan.rigid_slip(y0)
    relaxing = growth_slip(plan, form, sgn, u_s)
    if relaxing is not None:  # a growth area: sgn u relaxes (F = s a N + c rate u)
        J, K = _relaxing(plan, u_s, sgn * relaxing[1], relaxing[2], t - t0)
        if not find_stop or t.size == 0:
            return J, K, None
        T = float(t[-1])
        t_stop = float(relax_stop(*relaxing, t0, T, _slip_margin(plan, T)))
        return J, K, (t_stop if t_stop <= T else None)
    area = s.area if (np.asarray(form.c) != 0.0).any() else None
    t0_ = np.atleast_1d(np.asarray(t0, dtype=float))  # (1,) for a float: broadcasts against t as before

    # a half-sine N and a half-sine A of one contact time share the phase's cosine and sine
    shared = (isinstance(s.normal, HalfSineNormal) and isinstance(area, HalfSineArea)
              and np.array_equal(s.normal.contact_time, area.contact_time))

    def JK(tt):
        # terms that vanish (no area term; start at first contact) are skipped: a batch of many
        # scenes evaluates this on large grids
        trig = _half_sine_trig(area.contact_time, tt) if shared else None
        J, K = _normal_integrals(s.normal, tt, form.a, trig=trig)
        if (t0_ != 0.0).any():
            IN0, IIN0 = _normal_integrals(s.normal, t0_, form.a)
            J, K = J - IN0, K - (IIN0 + IN0 * (tt - t0))
        if area is not None:
            A, IA = _area_integrals(area, tt, trig=trig)
            A0, IA0 = _area_integrals(area, t0_)
            J, K = J + form.c * (A - A0), K + form.c * (IA - IA0 - A0 * (tt - t0))
        return (J, K) if (sgn == 1.0).all() else (sgn * J, sgn * K)

    def impulse(tt):
        # JK's J alone, by the same operations (tests/test_fit_path.py checks the two agree bit for bit)
        J = _normal_integrals(s.normal, tt, form.a, second=False)[0]
        if (t0_ != 0.0).any():
            J = J - _normal_integrals(s.normal, t0_, form.a, second=False)[0]
        if area is not None:
            J = J + form.c * (_area_integrals(area, tt, second=False)[0] - _area_integrals(area, t0_, second=False)[0])
        return J if (sgn == 1.0).all() else sgn * J

    J, K = JK(t)
    if not find_stop or t.size == 0:
        return J, K, None
    u_s = float(plan.rigid_slip(y0))

    def slip(tt):
        return u_s + plan.drive * (tt - t0) - plan.kappa * impulse(np.atleast_1d(tt))

    T = float(t[-1])
    # slip must pass zero by a hair (as in the ode solver's event): at a restart from rest,
    # round-off in the slip an ulp after t0 is not a new stop
    margin = _slip_margin(plan, T)
    if closed_stop_applies(plan, form, t0):  # slip falls monotonically: a stop iff it has passed zero at T
        if sgn * slip(T)[0] + margin > 0.0:
            return J, K, None
        return J, K, float(min(half_sine_stop(plan, form, u_s), T))
    line = _linear_slip(plan, form, sgn, u_s)
    if line is not None:
        return J, K, _line_stop(*line, t0, T, margin)
    wave = _pulse_slip(plan, form, sgn, u_s) if t0 == 0.0 and sgn * u_s > 0.0 else None
    if wave is not None:
        ts = float(pulse_stop(*wave, min(T, plan.scene.normal.contact_time), margin))
        return J, K, (ts if ts <= T else None)
    grid = np.unique(np.concatenate([np.linspace(t0, T, SCAN), t]))
    signed = sgn * slip(grid)
    g = signed + margin
    bad = np.nonzero(g[1:] <= 0.0)[0]
    if bad.size == 0:
        return J, K, None
    i = int(bad[0]) + 1
    xtol, rtol = 1e-15 * max(T, 1e-300), 4 * np.finfo(float).eps
    t_margin = float(grid[i]) if g[i] == 0.0 else brentq(lambda x: sgn * slip(x)[0] + margin, grid[i - 1], grid[i],
                                                         xtol=xtol, rtol=rtol)
    # the margin only detects the stop; the stop itself is where slip is zero, found from the
    # last time slip was strictly of the phase's sign (the closed form is exact, keep it so)
    ahead = np.nonzero(signed[:i] > 0.0)[0]  # the scan's values, not evaluated again
    if ahead.size == 0:
        return J, K, t_margin
    lo = float(grid[int(ahead[-1])])
    if sgn * slip(t_margin)[0] >= 0.0:
        return J, K, t_margin
    return J, K, float(brentq(lambda x: sgn * slip(x)[0], lo, t_margin, xtol=xtol, rtol=rtol))
