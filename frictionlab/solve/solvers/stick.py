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


def stuck_states(plan, t, ts, ys, out=None):
    """States at times t during a stuck phase that began at ts in state ys (closed form), and the force
    holding it (a read-only array of t's shape). Terms of a zero force or drive are skipped (a batch
    evaluates this on large grids; a rolling sphere needs neither); ``out`` may be ys itself."""
    s = plan.scene
    F = needed_force(plan)
    dt = np.asarray(t, dtype=float) - ts
    # without slip coupling the stuck body does not move (v = 0 exactly); with it the slip
    # v - r omega stays zero while both change
    a_v = plan.drive - F / s.mass if plan.coupled else 0.0
    spin = F * s.radius / s.inertia if plan.has_spin else 0.0
    out = np.empty((len(plan.states),) + dt.shape) if out is None else out
    # theta first: it reads the stuck phase's initial spin, which ``out`` may overwrite
    for i in sorted(range(len(plan.states)), key=lambda j: plan.states[j] != "theta"):
        name = plan.states[i]
        if name == "theta":
            w = ys[plan.index("omega")] * dt
            w += ys[i]
            if np.any(spin):
                w += 0.5 * spin * dt**2
            out[i] = w
        elif name == "v" and np.any(a_v):
            out[i] = ys[i] + a_v * dt
        elif name == "omega" and np.any(spin):
            out[i] = ys[i] + spin * dt
        elif out is not ys:
            out[i] = ys[i]
    return out, np.broadcast_to(F, dt.shape)
