"""The paper's first-order series, eqs (7)-(11), for F = k A u on the half-sine impact scene.

exp(b cos phi t - b) is replaced by 1 - b + b cos phi t (eq (7)); the force F = k A u of eq (3)
with that u, integrated as in eq (8), gives omega = omega_r + omega_a:
  omega_r = (5 u0 / 2r) b (1 - b)(1 - cos phi t),  omega_a = (5 u0 / 4r) b^2 sin^2 phi t
(written with r/I for a general moment of inertia). The truncated u is not a solution of the
equation of motion; b ~ 0.8 as in the paper is far outside the range where it is accurate.
"""
from __future__ import annotations

import math
import warnings

import numpy as np

from ...core.errors import SolverError
from ...physics.law import AreaSlipForm
from ...physics.scene import HalfSineArea
from ...physics.trajectory import Trajectory

#: Largest b for which the first-order series is called accurate: the series' u at t_c,
#: u0 (1 - 2b), differs from the exact u0 exp(-2b) by about 2 b^2 u0 (2% of u0 at b = 0.1).
B_ACCURATE = 0.1


class SeriesAccuracyWarning(UserWarning):
    """The first-order series is used outside the range where it is accurate."""


def slip_zero(t: np.ndarray, u: np.ndarray) -> float | None:
    """The first time a slip u(t) (positive at first) reaches zero, linearly interpolated; None if it does not.
    The truncated series' slip passes through zero (it is not a solution that stops there)."""
    i = np.nonzero(u <= 0.0)[0]
    if not len(i) or i[0] == 0:
        return None
    k = int(i[0])
    return float(t[k - 1] + (t[k] - t[k - 1]) * u[k - 1] / (u[k - 1] - u[k]))


def check(plan, p) -> AreaSlipForm:
    law, s = plan.law, plan.scene
    if law.states:
        raise SolverError(f"series: law '{law.name}' has internal state ({', '.join(law.state_names)}): the paper's "
                          "series does not apply; use --solver ode")
    form = law.form(p)
    if not isinstance(form, AreaSlipForm):
        raise SolverError(f"series: law '{law.name}' has no series solution (the paper's series, eqs (7)-(11), "
                          "is for laws of the form F = k A u); use the exact or ode solver")
    if not isinstance(s.area, HalfSineArea) or plan.drive != 0.0 or plan.coupled or "xi" in plan.states:
        raise SolverError("series: defined only on the paper's impact scene (half-sine area, no gravity, "
                          "no slip coupling, no compliance)")
    return form


def b_parameter(plan, p) -> float:
    """The paper's dimensionless b = k A0 / (m phi)."""
    form = check(plan, p)
    s = plan.scene
    return form.k * s.area.peak * s.area.contact_time / (s.mass * math.pi)


def solve(plan, p, t) -> Trajectory:
    form = check(plan, p)
    b = b_parameter(plan, p)
    if b > B_ACCURATE:
        warnings.warn(f"series: b = {b:.3g} exceeds {B_ACCURATE}; the first-order series (eq 7) is accurate only "
                      f"for b << 1 (its slip at t_c is off by about 2 b^2 u0 = {2 * b * b:.2g} u0)",
                      SeriesAccuracyWarning, stacklevel=3)
    t = np.asarray(t, dtype=float)
    out = curves(plan, form.k, t)
    return Trajectory(t=t, **out, solver="series", law=plan.law.name, info={"b": b})


def curves(plan, k, t: np.ndarray) -> dict[str, np.ndarray]:
    """u, v, omega, theta, force [SI] and A (where the plan needs it) on times t [s] for F = k A u; k [Pa s/m]
    a number, or an (m, 1) column of m parameter sets (then each curve is (m, len(t)): ``predict.predict_array``)."""
    s = plan.scene
    tc = s.area.contact_time
    phi = math.pi / tc
    b = k * s.area.peak * tc / (s.mass * math.pi)
    u0 = s.u0
    tau = np.minimum(t, tc)
    c, sn = np.cos(phi * tau), np.sin(phi * tau)
    u = u0 * (1.0 - b + b * c)
    A, _ = s.area(t)
    force = k * A * u
    J = k * s.area.peak * u0 / phi * ((1.0 - b) * (1.0 - c) + b * sn * sn / 2.0)
    K = k * s.area.peak * u0 / phi * ((1.0 - b) * (tau - sn / phi) + b / 2.0 * (tau / 2.0 - np.sin(2 * phi * tau) / (4 * phi)))
    J_end = k * s.area.peak * u0 / phi * 2.0 * (1.0 - b)
    K = K + J_end * np.maximum(t - tc, 0.0)
    omega = theta = np.zeros_like(u)
    if plan.has_spin:
        omega = s.omega0 + s.radius * J / s.inertia
        theta = s.omega0 * t + s.radius * K / s.inertia
    return {"u": u, "v": u.copy(), "omega": omega, "theta": theta, "force": force,
            "A": (A if A.shape == u.shape else np.broadcast_to(A, u.shape)) if plan.needs_area else None}
