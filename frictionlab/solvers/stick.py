"""Zero slip as an event, shared by the exact and ODE solvers.

When slip reaches zero the contact sticks (a sphere with slip coupling rolls). While stuck,
friction supplies exactly the force that keeps slip at zero, F_need = drive / kappa, as long
as the law can: its force at vanishing slip in that direction (its capacity) must be at least
|F_need|. When the capacity drops below it, sliding resumes in the direction of the drive.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

GRID = 512  # points scanned per segment when looking for breakaway


def needed_force(plan) -> float:
    """Friction force that holds slip at zero [N]."""
    return plan.drive / plan.kappa


def vanishing_slip(plan):
    """The small slip magnitude [m/s] at which a law's force 'at zero slip' is evaluated."""
    return 1e-12 * np.maximum(np.abs(plan.scene.u0), 1e-3)


def branch_slip(plan, u, direction):
    """Slip the law sees during a sliding phase in ``direction``: a Runge-Kutta stage that overshoots
    zero slip sees vanishing slip on the phase's side, so the phase's force law continues smoothly and
    the zero-slip event ends the phase. (Letting the force flip there makes slip chatter about zero,
    a sliding mode, and the integrator crawl towards an event that never comes.)"""
    return np.where(direction * u > 0, u, direction * vanishing_slip(plan))


def capacity(plan, p, t, y, direction: float) -> np.ndarray:
    """The law's force at vanishing slip in ``direction`` (+1 or -1), at times t for stuck state y."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    tiny = direction * vanishing_slip(plan)
    yy = np.repeat(np.asarray(y, dtype=float)[:, None], t.size, axis=1)
    f, _ = plan.force(p, t, yy, np.full(t.size, tiny))
    return direction * f


def hold_direction(plan, slip_before: float) -> float:
    f = needed_force(plan)
    return float(np.sign(f)) if f != 0 else float(np.sign(slip_before) or 1.0)


def breakaway(plan, p, t0: float, t1: float, y0, slip_before: float) -> float | None:
    """First time in [t0, t1] at which the law can no longer hold the contact, or None."""
    need = abs(needed_force(plan))
    direction = hold_direction(plan, slip_before)
    grid = np.linspace(t0, t1, GRID)
    # the stuck state changes only through omega/theta, which no law reads: y0 is enough
    cap = capacity(plan, p, grid, y0, direction)
    # a capacity equal to the need up to rounding (mu = tan(alpha) exactly) holds: without this
    # tolerance the contact would break away and stick again at once, forever
    tol = 64 * np.finfo(float).eps * max(need, float(np.max(np.abs(cap))))
    margin = cap - need
    bad = np.nonzero(margin < -tol)[0]
    if bad.size == 0:
        return None
    i = int(bad[0])
    if i == 0:
        return t0
    g = lambda s: capacity(plan, p, s, y0, direction)[0] - need + tol  # noqa: E731
    return brentq(g, grid[i - 1], grid[i], xtol=1e-15 * max(t1, 1e-300))


def stuck_states(plan, t, ts, ys):
    """States at times t during a stuck phase that began at ts in state ys (closed form)."""
    s = plan.scene
    F = needed_force(plan)
    dt = np.asarray(t, dtype=float) - ts
    out = {}
    # without slip coupling the stuck body does not move (v = 0 exactly); with it the slip
    # v - r omega stays zero while both change
    a_v = plan.drive - F / s.mass if plan.coupled else 0.0
    for i, name in enumerate(plan.states):
        if name == "v":
            out[name] = ys[i] + a_v * dt
        elif name == "omega":
            out[name] = ys[i] + F * s.radius / s.inertia * dt
        elif name == "theta":
            out[name] = ys[i] + ys[plan.index("omega")] * dt + 0.5 * F * s.radius / s.inertia * dt**2
        else:
            out[name] = np.full(dt.shape, ys[i])
    return np.array([out[k] for k in plan.states]), np.full(dt.shape, F)
