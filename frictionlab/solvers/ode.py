"""Numerical integration with scipy's solve_ivp, on a scaled problem, with zero slip as an event.

Time is scaled by the simulated span and each state by its typical size, so that one pair of
tolerances means the same thing for a 1 ns and a 1 s contact, for 1e-12 and 1 m^2 areas.
"""
from __future__ import annotations

import numbers

import numpy as np
from scipy.integrate import solve_ivp

from ..errors import SolverError

METHODS = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")

#: Right-hand-side evaluations one sliding phase may take before it is stopped with an error (a
#: problem too stiff for the method, e.g. rate-and-state friction as slip reaches zero).
MAX_NFEV = 20_000

#: Slip, relative to its scale, by which the zero-slip event waits past zero (see zero_slip).
SLIP_MARGIN = 1e-12


def state_scales(plan, T: float) -> np.ndarray:
    """Typical size of each state; shape (n_states,), or (n_states, n) for a batch view with array fields."""
    s = plan.scene
    r = 1.0 if s.radius is None else s.radius
    V = np.maximum(np.maximum(np.abs(s.u0), np.abs(plan.drive) * T), np.abs(s.omega0) * (0.0 if s.radius is None else r))
    V = np.where(V > 1e-300, V, 1.0)
    size = {"v": V, "omega": V / r, "theta": V * T / r, "x": V * T, "xi": V * T, **law_state_scales(plan)}
    return np.array(np.broadcast_arrays(*[size[k] for k in plan.states]), dtype=float)


def law_state_scales(plan) -> dict[str, float]:
    """The declared scale of each internal state of the plan's law, by plan name ("law:z")."""
    return {k: spec.scale for k, spec in zip(plan.law_states, plan.law.states)}


def phase_scales(plan, p, t0: float, T: float, y0, direction: float) -> np.ndarray:
    """Typical size of each state over a sliding phase [t0, T], so that tolerances act relative to it.

    Velocities scale with the largest of the initial slip and body speed, and the speed the
    drive can reach: |drive| (T - t0), or less where the law's force at that speed exceeds
    the drive (a lubricated block levels off at u_inf << g T). Spin and angle scale with the
    friction impulse the law can deliver, J ~ min(F (T - t0), (V + |drive| T) / kappa), F the
    law's largest force at slip V over the span: with a weak law (b = 1e-6) spin is tiny, and
    scaling it by V / r would leave it to the absolute tolerance alone.
    """
    s = plan.scene
    r = s.radius or 1.0
    span = max(T - t0, T * 1e-12, 1e-300)
    tt = np.linspace(t0, T, 33)
    yy = np.repeat(np.asarray(y0, dtype=float)[:, None], tt.size, axis=1)

    def largest_force(u):
        F, _ = plan.force(p, tt, yy, np.full(tt.size, u))
        return float(np.max(np.abs(F)))

    V = max(abs(s.u0), abs(float(y0[0])), abs(float(plan.rigid_slip(y0))), abs(s.omega0) * r)
    if plan.drive != 0.0:
        reach = abs(plan.drive) * span
        F = largest_force(np.sign(plan.drive) * reach)
        V = max(V, reach * min(1.0, s.mass * abs(plan.drive) / F) if F > 0 else reach)
    V = V if V > 0 and np.isfinite(V) else 1.0
    if s.spring is not None:  # the load point sets the speeds
        V = max(V, max(s.spring.velocities))
    size = {"v": V, "x": V * span, "xi": V * span, **law_state_scales(plan)}
    if plan.has_spin:
        J = min(largest_force((direction or 1.0) * V) * span, (V + abs(plan.drive) * span) / plan.kappa)
        w = max(r * J / s.inertia, abs(s.omega0), 1e-12 * V / r)
        size["omega"] = w
        size["theta"] = max(w * span, abs(float(y0[plan.index("theta")])), 1e-300)
    return np.array([size[k] for k in plan.states])


def make_slide(method: str = "LSODA", rtol: float = 1e-10, atol: float | None = None):
    """A sliding-phase function for ``segments.run`` using solve_ivp ``method``."""
    if method not in METHODS:
        raise SolverError(f"unknown ODE method {method!r}; choose one of {', '.join(METHODS)}")
    if isinstance(rtol, bool) or not isinstance(rtol, numbers.Real) or not (0 < rtol < 1):
        raise SolverError(f"rtol must be a number in (0, 1), got {rtol!r}")
    atol = rtol if atol is None else atol
    if isinstance(atol, bool) or not isinstance(atol, numbers.Real) or not (0 < atol < float("inf")):
        raise SolverError(f"atol must be a positive number, got {atol!r}")

    def slide(plan, p, t0, y0, direction, t_out):
        if len(t_out) == 0 or t_out[-1] <= t0:
            return np.repeat(np.asarray(y0, dtype=float)[:, None], len(t_out), axis=1), None, None, {"nfev": 0}
        T = float(t_out[-1])
        scale = phase_scales(plan, p, t0, T, y0, direction)
        tscale = T
        compliant = "xi" in plan.states

        calls = [0]

        def f(s, z):
            calls[0] += 1
            if calls[0] > MAX_NFEV:
                raise SolverError(f"ode:{method}: law '{plan.law.name}' needed more than {MAX_NFEV} right-hand-side "
                                  f"evaluations (stopped at t = {s * tscale:.6g} s): too stiff for {method} here")
            return plan.derivatives(p, s * tscale, z * scale, direction) * tscale / scale

        events = None
        if not compliant and direction != 0:
            def zero_slip(s, z):
                # fires once slip has passed zero by a hair (SLIP_MARGIN of its scale), so that
                # round-off at a restart from rest (slip exactly 0) is not taken for a new stop
                return float(plan.rigid_slip(z * scale)) / scale[0] + direction * SLIP_MARGIN

            zero_slip.terminal = True
            zero_slip.direction = -direction
            events = [zero_slip]
        s_eval = np.clip(np.asarray(t_out, dtype=float) / tscale, t0 / tscale, T / tscale)
        s_eval, back = np.unique(s_eval, return_inverse=True)  # repeated times (e.g. a resample) solved once
        # where the right-hand side jumps (a load-point velocity step) the integration restarts
        cuts = [b / tscale for b in plan.breaks if t0 < b < T] if events is None else []
        edges = [t0 / tscale] + cuts + [T / tscale]
        z0, parts, stats = np.asarray(y0, dtype=float) / scale, [], {"nfev": 0, "njev": 0, "nlu": 0}
        try:
            for k, (a, b) in enumerate(zip(edges[:-1], edges[1:])):
                last = k == len(edges) - 2
                inside = s_eval[(s_eval >= a) & ((s_eval <= b) if last else (s_eval < b))]
                sol = solve_ivp(f, (a, b), z0, method=method, t_eval=np.append(inside, b) if not last else inside,
                                rtol=rtol, atol=atol, events=events)
                if sol.status == -1:
                    raise SolverError(f"ode:{method}: integration failed for law '{plan.law.name}': {sol.message}")
                for key in stats:
                    stats[key] += int(getattr(sol, key))
                if last:
                    parts.append(sol.y)
                else:
                    parts.append(sol.y[:, :-1])
                    z0 = sol.y[:, -1]
        except Exception as exc:  # a law raising inside the integrator
            from ..errors import FrictionLabError

            if isinstance(exc, FrictionLabError):
                raise
            raise SolverError(f"ode:{method}: integration failed for law '{plan.law.name}': {exc}") from exc
        sol.y = np.concatenate(parts, axis=1)
        Y = sol.y[:, back[back < sol.y.shape[1]]] * scale[:, None]  # a stop ends the samples reached
        t_stop = y_stop = None
        if events is not None and sol.t_events[0].size:
            t_stop = float(sol.t_events[0][0]) * tscale
            y_stop = sol.y_events[0][0] * scale
        info = {**stats, "method": method, "rtol": rtol, "atol": atol}
        return Y, t_stop, y_stop, info

    return slide


