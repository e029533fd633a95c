"""What a user writes without frictionlab for the work-precision cases: scipy's solve_ivp on a plain Python
right-hand side of the same scaled problem (``frictionlab.pipeline.bench``'s 'scipy:METHOD (plain)' lines)."""
from __future__ import annotations

import math

import numpy as np

from ..physics.scene import G, GrowthArea, HalfSineArea


def _friction(law, params, scene):
    """F(t, u, x) [N] of the bench's Coulomb, wear and Couette cases, on plain floats."""
    area, normal = scene.area, scene.normal
    k = params["lam"] if law == "wear" else (params["eta"] / params["h"] if law == "couette" else 0.0)
    mu = params.get("mu", 0.0)

    def friction(t, u, x):
        if law == "coulomb":
            tc, peak = normal.contact_time, normal.impulse * math.pi / (2.0 * normal.contact_time)
            return mu * (peak * math.sin(math.pi * t / tc) if t < tc else 0.0) * (1.0 if u > 0 else -1.0)
        if isinstance(area, HalfSineArea):
            a = area.peak * math.sin(math.pi * t / area.contact_time) if t < area.contact_time else 0.0
        elif isinstance(area, GrowthArea):
            a = area.initial + area.rate * x
        else:
            a = area.area
        return k * a * u

    return friction


def plain_solver(law, params, scene):
    """solve_ivp on a plain Python right-hand side of the same scaled problem (time by the span, velocities
    by u0 or the drive's reach, as ``solvers.ode.state_scales``), with slip reaching zero as a terminal
    event after which the ball rolls (slip 0, spin constant). Returns solve(method, rtol, t) -> Trajectory-like."""
    from types import SimpleNamespace

    from scipy.integrate import solve_ivp

    from ..physics.registry import get_law
    from ..solve.plan import make_plan
    from ..solve.solvers.ode import state_scales

    plan = make_plan(scene, get_law(law))
    T = scene.duration
    sc = state_scales(plan, T)
    m, r = scene.mass, scene.radius or 0.0
    inertia = 0.4 * m * r * r if scene.radius else 1.0
    drive = G * math.sin(scene.incline) if "gravity" in scene.effects else 0.0
    coupled, spin = plan.coupled, plan.has_spin
    friction = _friction(law, params, scene)
    names = plan.states

    def rhs(s, z):
        t = s * T
        y = z * sc
        v = y[0]
        u = v - r * y[1] if coupled else v
        F = friction(t, u, y[names.index("x")] if "x" in names else 0.0)
        rates = {"v": drive - F / m, "omega": F * r / inertia, "theta": y[1] if spin else 0.0, "x": abs(u)}
        return [rates[n] * T / sc[i] for i, n in enumerate(names)]

    def slip(s, z):
        return (z[0] * sc[0] - r * z[1] * sc[1]) / sc[0] if coupled else z[0]

    slip.terminal, slip.direction = True, -1

    def solve(method, rtol, t):
        y0 = np.array([scene.u0 if n == "v" else 0.0 for n in names])
        sol = solve_ivp(rhs, (0.0, 1.0), y0 / sc, method=method, t_eval=t / T, rtol=rtol, atol=rtol,
                        events=slip if scene.u0 != 0 else None)  # from rest on an incline slip only grows
        reached = sol.y.shape[1]
        Y = np.empty((len(names), t.size))
        Y[:, :reached] = sol.y * sc[:, None]
        if reached < t.size:  # slip stopped: the ball rolls on, spin frozen, angle growing with it
            te, ye = sol.t_events[0][0] * T, sol.y_events[0][0] * sc
            Y[:, reached:] = ye[:, None]
            if spin:
                Y[2, reached:] = ye[2] + ye[1] * (t[reached:] - te)
        omega = Y[1] if spin else np.zeros(t.size)
        u = Y[0] - r * omega if coupled else Y[0].copy()
        u[reached:] = 0.0
        return SimpleNamespace(u=u, omega=omega, theta=Y[2] if spin else np.zeros(t.size),
                               info={"nfev": int(sol.nfev)})

    return solve
