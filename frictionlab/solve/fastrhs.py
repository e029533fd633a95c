"""The scalar ODE right-hand side of a built-in law's closed-form family on plain floats.

Every scalar ODE solve (``solvers.ode``) of a memoryless law calls ``Plan.bound``'s f(t, y) tens of
times per step; ``Plan._one_state`` evaluates it through the scene's models and the law's ``force`` on
arrays. For the built-in laws of the closed-form families (F = k A u, or F = sign(u) (a N + c dA/dt): see
``physics.law``), on scenes whose area and normal-force models are written out here (half-sine, constant,
growth; half-sine, constant, weight), ``scalar_rhs`` gives the same derivatives from the law's form with
float arithmetic, about a third of the cost. The form's coefficients group the law's products
differently (area-rate's mu eta' dA/dt), so results agree to rounding, not bitwise
(tests/test_fastrhs.py checks them against ``_one_state`` and whole fits against the general path).
Anything else, and any non-finite force (the general path then raises the law's one-line error), takes
``_one_state``.
"""
from __future__ import annotations

import math

import numpy as np

from ..physics.law import AreaSlipForm, NormalAreaRateForm
from ..physics.scene import ConstantArea, ConstantNormal, GrowthArea, HalfSineArea, HalfSineNormal, WeightNormal


def _area(model):
    """(A, dA/dt) [m^2, m^2/s] at one time t [s], sliding length x [m] and slip u [m/s], or None."""
    if type(model) is HalfSineArea:
        peak, tc = float(model.peak), float(model.contact_time)
        phi = math.pi / tc

        def half_sine(t, x, u):
            if 0.0 <= t <= tc:
                return peak * math.sin(phi * t), peak * phi * math.cos(phi * t)
            return 0.0, 0.0

        return half_sine
    if type(model) is ConstantArea:
        a = float(model.area)
        return lambda t, x, u: (a, 0.0)
    if type(model) is GrowthArea:
        a0, rate = float(model.initial), float(model.rate)
        return lambda t, x, u: (a0 + rate * x, rate * abs(u))
    return None


def _normal(model):
    """N [N] at one time t [s], or None."""
    if type(model) is HalfSineNormal:
        peak, tc = float(model.peak), float(model.contact_time)
        phi = math.pi / tc
        return lambda t: peak * math.sin(phi * t) if 0.0 <= t <= tc else 0.0
    if type(model) in (ConstantNormal, WeightNormal):
        n = float(model.value)
        return lambda t: n
    return None


def _force(form, plan):
    """F(t, x, u) [N] of the form on the plan's scene, or None where a model is not written out here."""
    s = plan.scene
    if isinstance(form, AreaSlipForm):
        area = _area(s.area) if plan.needs_area else None
        if area is None:
            return None
        k = float(form.k)
        return lambda t, x, u: k * area(t, x, u)[0] * u
    if not isinstance(form, NormalAreaRateForm):
        return None
    normal = _normal(s.normal) if plan.needs_normal else None
    a, c = float(form.a), float(form.c)
    area = _area(s.area) if c != 0.0 and plan.needs_area else None
    if normal is None or (c != 0.0 and area is None):
        return None
    if c == 0.0:
        return lambda t, x, u: (a * normal(t)) * ((u > 0.0) - (u < 0.0))
    return lambda t, x, u: (a * normal(t) + c * area(t, x, u)[1]) * ((u > 0.0) - (u < 0.0))


def scalar_rhs(plan, p, direction: float, vanishing: float = 0.0):
    """f(t, y) -> dy/dt for one state vector y of ``plan`` (see the module), or None where it does not apply.
    vanishing: the slip [m/s] (``solvers.stick.vanishing_slip``) held while the phase's slip has not yet
    got its direction's sign."""
    law, s = plan.law, plan.scene
    if (not type(law).__module__.startswith("frictionlab.laws.") or law.states or s.spring is not None
            or not set(plan.states) <= {"v", "omega", "theta", "x"}):
        return None
    force = _force(law.form(p), plan)
    if force is None:
        return None
    names = plan.states
    iw = plan.index("omega") if plan.has_spin else 0
    ix = plan.index("x") if "x" in names else -1
    r = float(s.radius) if plan.coupled or plan.has_spin else 0.0
    coupled, spin = plan.coupled, plan.has_spin
    m, drive = float(s.mass), float(plan.drive)
    inertia = float(s.inertia) if spin else 1.0
    tiny = direction * vanishing
    general = plan._one_state

    def rhs(t, y):
        v = float(y[0])
        u = v - r * float(y[iw]) if coupled else v
        if direction != 0.0 and not direction * u > 0:
            u = tiny
        F = float(force(t, float(y[ix]) if ix >= 0 else 0.0, u))
        if not math.isfinite(F):
            return general(p, t, y, direction)  # the law's one-line error, from the general path
        rate = {"v": drive - F / m, "x": abs(u)}
        if spin:
            rate["omega"] = F * r / inertia
            rate["theta"] = float(y[iw])
        return np.array([rate[k] for k in names])

    return rhs


def scaled_slip_rhs(plan, p, direction: float, vanishing: float, tscale: float, scale, general):
    """``scalar_rhs`` of a law of the form F = k A u on a block without spin (states v, or v and x) on the scaled
    problem of a phase (time / tscale, states / scale), with floats throughout: f(s, z) -> (dz/ds), the phases of
    ``solvers.ode.slip_keeps_sign``, whose right-hand side is called tens of thousands of times a fit from
    ODEPACK's loop. None where ``scalar_rhs`` would not serve; ``general(s, z)``, the scaled general right-hand
    side, answers where the force is not finite (with the law's one-line error)."""
    if scalar_rhs(plan, p, direction, vanishing) is None or plan.states not in (("v",), ("v", "x")):
        return None
    form, area = plan.law.form(p), _area(plan.scene.area)
    if not isinstance(form, AreaSlipForm) or area is None:
        return None
    k, m, drive, tiny = float(form.k), float(plan.scene.mass), float(plan.drive), direction * vanishing
    sv, cv = float(scale[0]), tscale / float(scale[0])
    slid = len(plan.states) == 2  # x, the slip so far, is a state: the area may depend on it
    sx = float(scale[1]) if slid else 1.0
    cx = tscale / sx

    def f(s, z):
        u = float(z[0]) * sv
        if not direction * u > 0:
            u = tiny
        F = k * area(s * tscale, float(z[1]) * sx if slid else 0.0, u)[0] * u
        if not math.isfinite(F):
            return general(s, z)
        return ((drive - F / m) * cv, abs(u) * cx) if slid else ((drive - F / m) * cv,)

    return f
