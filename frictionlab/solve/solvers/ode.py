"""Numerical integration with scipy's ODE solvers, on a scaled problem, with zero slip as an event.

Time is scaled by the simulated span and each state by its typical size, so that one pair of
tolerances means the same thing for a 1 ns and a 1 s contact, for 1e-12 and 1 m^2 areas.
``solve`` is scipy's ``solve_ivp`` loop for the one case used here (sorted output times, at most
one terminal event on a scalar function): the same solver steps, dense output and event root, so
the same numbers (a test checks them against solve_ivp), without its per-step generality.
"""
from __future__ import annotations

import bisect
import contextlib
import numbers

import numpy as np
import scipy.integrate
from scipy.optimize import brentq

from ...core.errors import FrictionLabError, SolverError
from ..memory_codes import CALLS, SENSE, TOO_MANY, TURNED

METHODS = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")

#: Right-hand-side evaluations one sliding phase may take before it is stopped with an error (a
#: problem too stiff for the method; Radau at rtol 1e-12 on the bench's LuGre impact takes 26,000).
MAX_NFEV = 50_000

#: Slip, relative to its scale, by which the zero-slip event waits past zero (see zero_slip).
SLIP_MARGIN = 1e-12


#: Callbacks told the time reached after each step (``watching``); the innermost is called.
_WATCHERS: list = []


@contextlib.contextmanager
def watching(fn):
    """Call ``fn(t)`` with the time reached after every step of every integration inside the block (for
    progress on a long single solve; the command line's ``simulate``)."""
    _WATCHERS.append(fn)
    try:
        yield
    finally:
        _WATCHERS.remove(fn)


def solve(f, s0: float, s1: float, z0, method: str, s_eval, rtol: float, atol: float, event=None,
          event_direction: float = 0.0, label: str = "integration failed", jac=None, compiled=None,
          odepack: bool = False):
    """Integrate z' = f(s, z) from s0 to s1 with scipy's ``method`` and return
    (Z at the times s_eval reached (n_states, k), s_event or None, z_event or None, the solver).

    s_eval: increasing times within [s0, s1]. event(s, z) -> float: a terminal event where it crosses
    zero in ``event_direction`` (as in solve_ivp: < 0 falling, > 0 rising, 0 either way), located by
    brentq on the step's dense output to 4 eps, exactly as solve_ivp does. A failed step raises
    SolverError('{label}: {scipy's message}'). jac(s, z): the Jacobian df/dz for the implicit methods (None:
    they difference f). LSODA with no event runs its whole loop in ODEPACK (``_lsoda_loop``) on a compiled
    right-hand side (``compiled``, a ``memoryrhs.Phase``), or on f where ``odepack`` says so (``slip_keeps_sign``).
    """
    if method == "LSODA" and event is None and not _WATCHERS and (compiled is not None or odepack):
        if compiled is not None:
            return _lsoda_loop(compiled.kernel.rhs, compiled.kernel.jac, compiled.args, s0, s1, z0, s_eval, rtol,
                               atol, label)
        return _lsoda_loop(f, jac, (), s0, s1, z0, s_eval, rtol, atol, label)
    eps = np.finfo(float).eps
    kw = {"jac": jac} if jac is not None and method in ("Radau", "BDF", "LSODA") else {}
    solver = getattr(scipy.integrate, method)(f, s0, np.asarray(z0, dtype=float), s1, rtol=rtol, atol=atol, **kw)
    s_eval = np.asarray(s_eval, dtype=float)
    eval_list = s_eval.tolist()  # bisect on floats: np.searchsorted's index, without its per-step dispatch
    outs, i = [], 0
    g = event(s0, solver.y) if event is not None else None
    s_event = z_event = None
    while True:
        message = solver.step()
        if solver.status == "failed":
            raise SolverError(f"{label}: {message}")
        s, z, sol = solver.t, solver.y, None
        if _WATCHERS:
            _WATCHERS[-1](s)
        if event is not None:
            g_new = event(s, z)
            up, down = g <= 0 <= g_new, g >= 0 >= g_new
            if (up and event_direction > 0) or (down and event_direction < 0) or ((up or down) and event_direction == 0):
                sol = solver.dense_output()
                s = s_event = brentq(lambda x: event(x, sol(x)), solver.t_old, s, xtol=4 * eps, rtol=4 * eps)
                z = z_event = sol(s)
            g = g_new
        j = bisect.bisect_right(eval_list, s)
        if j > i:
            outs.append((sol or solver.dense_output())(s_eval[i:j]))
            i = j
        if s_event is not None or solver.status == "finished":
            break
    Z = np.hstack(outs) if outs else np.empty((len(z0), 0))
    return Z, s_event, z_event, solver


def _lsoda_loop(rhs, jac, args, s0, s1, z0, s_eval, rtol, atol, label):
    """``solve`` for LSODA without an event: scipy's ``odeint``, the same ODEPACK LSODA that ``solve_ivp`` steps
    one call at a time, here with its stepping loop and output interpolation in Fortran (it calls rhs(s, z, *args)
    and jac, a compiled kernel's or None for differences, directly) and the end of the span as its critical time
    (no step beyond it), as ``solve_ivp`` steps."""
    import warnings
    from types import SimpleNamespace

    s_eval = np.asarray(s_eval, dtype=float)
    times = np.concatenate([[s0], s_eval, [s1]])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            Z, info = scipy.integrate.odeint(rhs, np.asarray(z0, dtype=float), times, args=args, Dfun=jac,
                                             tfirst=True, rtol=rtol, atol=atol, tcrit=[s1], full_output=True,
                                             mxstep=MAX_NFEV)
        except FloatingPointError:  # a compiled kernel stopped (its phase's ``bad`` says why)
            raise SolverError(f"{label}: the compiled right-hand side stopped") from None
    if info["message"] != "Integration successful.":
        raise SolverError(f"{label}: {info['message']}")
    used = {"nfev": int(info["nfe"][-1]), "njev": int(info["nje"][-1]), "nlu": int(info["nje"][-1])}
    return Z[1:-1].T, None, None, SimpleNamespace(y=Z[-1].copy(), t=s1, **used)


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
    size = {"v": V, "x": V * span, "xi": V * span, "load": 1.0, **law_state_scales(plan)}
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
        event = _zero_slip_event(plan, direction, scale)
        for slid in (True, False):
            fast = _memory_phase(plan, p, direction, T, y0, scale, slid)
            if fast is None:
                break
            try:
                Y, t_stop, y_stop, info = _integrate_phase(plan, fast.f, event, t0, T, fast.y0, direction, t_out,
                                                           fast.scale, method, rtol, atol,
                                                           fast.jac if method in IMPLICIT else None, fast)
                return fast.states(Y), t_stop, fast.states(y_stop), info
            except SolverError:
                if fast.bad == TOO_MANY:
                    raise SolverError(f"ode:{method}: {_too_many(plan, fast.stop_time, method)}") from None
                if fast.bad != TURNED:
                    break  # a value not finite or a failed step: the general path's to handle or to say
            try:  # Dahl's slip turned: slid phases from turn to turn
                return _turns(plan, p, t0, T, y0, float(fast.C[SENSE]), t_out, scale, method, rtol, atol)
            except SolverError:
                if fast.bad == TOO_MANY:
                    raise SolverError(f"ode:{method}: {_too_many(plan, fast.stop_time, method)}") from None
        f = _scaled_rates(plan, p, direction, T, scale, method)
        odepack = method == "LSODA" and event is not None and slip_keeps_sign(plan, p, direction)
        if odepack:
            lean = _lean_slip_rates(plan, p, direction, T, scale, f)
            f = f if lean is None else _counted(lean, plan, T, method)
        try:
            return _integrate_phase(plan, f, None if odepack else event, t0, T, y0, direction, t_out, scale, method,
                                    rtol, atol, odepack=odepack)
        except SolverError as exc:  # name what in the scene makes it fail, where the plan knows
            note = plan.stiffness_note(p, t0, y0) if method not in ("BDF", "Radau") else ""
            if note:
                raise SolverError(f"{str(exc).rstrip('.')}; {note}") from None
            raise

    return slide


def _turns(plan, p, t0, T, y0, sense, t_out, scale, method, rtol, atol):
    """A Dahl phase in the slid form (``memoryrhs``) as a chain of phases of one slip sense each, the next one
    begun where the slip turns (an event: slip past zero by SLIP_MARGIN of its scale), from the friction reached
    there; SolverError past MAX_TURNS turns (then mu_d is integrated instead) or MAX_NFEV calls."""
    from ..memoryrhs import MAX_TURNS, phase

    t_out = np.asarray(t_out, dtype=float)
    Y = np.empty((len(plan.states), t_out.size))
    done, t, y, calls, stats = 0, t0, np.asarray(y0, dtype=float), 0, {"nfev": 0, "njev": 0, "nlu": 0}
    iw = plan.index("omega") if plan.coupled else 0
    r, sv = (plan.scene.radius if plan.coupled else 0.0), float(scale[0])
    for _ in range(MAX_TURNS):
        ph = phase(plan, p, 0.0, 0.0, T, y, scale, MAX_NFEV - calls, True, sense)
        turn = (lambda s, z, sw=float(ph.scale[iw]), k=sense:
                k * (z[0] * sv - r * (z[iw] * sw)) / sv + SLIP_MARGIN)
        try:
            Ys, t_stop, y_stop, info = _integrate_phase(plan, ph.f, turn, t, T, ph.y0, 1.0, t_out[done:], ph.scale,
                                                        method, rtol, atol, ph.jac if method in IMPLICIT else None,
                                                        ph)
        finally:
            calls += int(ph.C[CALLS])
        Y[:, done:done + Ys.shape[1]] = ph.states(Ys)
        done += Ys.shape[1]
        for k in stats:
            stats[k] += info[k]
        if t_stop is None:
            return Y, None, None, {**info, **stats}
        t, y, sense = t_stop, ph.states(y_stop[:, None])[:, 0], -sense
    raise SolverError(f"ode:{method}: Dahl's slip turned more than {MAX_TURNS} times")


#: The methods that take a Jacobian.
IMPLICIT = ("Radau", "BDF", "LSODA")


def _too_many(plan, t, method) -> str:
    return (f"law '{plan.law.name}' needed more than {MAX_NFEV} right-hand-side evaluations (stopped at t = {t:.6g} s): "
            f"too stiff for {method} here")


def _scaled_rates(plan, p, direction, tscale, scale, method):
    """The right-hand side of a sliding phase on the scaled problem (time / tscale, states / scale), through
    ``Plan.bound``; it stops with a clear error beyond MAX_NFEV evaluations (``_counted``)."""
    rates = plan.bound(p, direction)
    return _counted(lambda s, z: rates(s * tscale, z * scale) * tscale / scale, plan, tscale, method)


def _lean_slip_rates(plan, p, direction, tscale, scale, general):
    """``fastrhs.scaled_slip_rhs`` for a phase of ``slip_keeps_sign``, or None."""
    from ..fastrhs import scaled_slip_rhs
    from .stick import vanishing_slip

    return scaled_slip_rhs(plan, p, direction, float(vanishing_slip(plan)), tscale, scale, general)


def _counted(f, plan, tscale, method):
    """f(s, z) of a phase's scaled problem, stopped with a clear error beyond MAX_NFEV evaluations."""
    calls = [0]

    def counted(s, z):
        calls[0] += 1
        if calls[0] > MAX_NFEV:
            raise SolverError(f"ode:{method}: {_too_many(plan, s * tscale, method)}")
        return f(s, z)

    return counted


def slip_keeps_sign(plan, p, direction) -> bool:
    """Whether the slip of a sliding phase cannot reach zero, so that no zero-slip event is watched: a law of the
    form F = k A u (``AreaSlipForm``) on a body without spin, driven in the slip's direction. At u = 0 its force
    vanishes whatever the area, so du/dt = the drive, of the slip's sign: the slip tends to a speed the drive
    holds, never through zero (an inclined block with lubricated or wear friction)."""
    from ...physics.law import AreaSlipForm

    if direction == 0 or plan.coupled or plan.has_spin or plan.scene.spring is not None or plan.law_states:
        return False
    try:
        form = plan.law.form(p)
    except Exception:  # a plugin's form that fails: the event stays
        return False
    return isinstance(form, AreaSlipForm) and direction * plan.drive > 0


def _zero_slip_event(plan, direction, scale):
    """The zero-slip event of a sliding phase on the scaled problem, or None (no direction, or compliance)."""
    if "xi" in plan.states or direction == 0:
        return None
    r, iw = (plan.scene.radius, plan.index("omega")) if plan.coupled else (0.0, 0)
    sv, sw = float(scale[0]), float(scale[iw])

    def zero_slip(s, z):
        # slip / its scale (plan.rigid_slip on the scaled state), fired once slip has passed zero by a
        # hair (SLIP_MARGIN of its scale), so that round-off at a restart from rest is not a new stop
        return (z[0] * sv - r * (z[iw] * sw)) / sv + direction * SLIP_MARGIN

    return zero_slip


def _memory_phase(plan, p, direction, tscale, y0, scale, slid=True):
    """``memoryrhs.phase``: the compiled right-hand side and Jacobian of a built-in law with memory on a scene
    written out there, for this phase; None where it does not serve."""
    if not plan.law_states:
        return None
    from ..memoryrhs import phase
    from .stick import vanishing_slip

    return phase(plan, p, float(direction), float(vanishing_slip(plan)) if direction != 0 else 0.0, tscale, y0,
                 scale, MAX_NFEV, slid)


def _integrate_phase(plan, f, event, t0, T, y0, direction, t_out, scale, method, rtol, atol, jac=None, compiled=None,
                     odepack: bool = False):
    """solve_ivp over [t0, T] (restarted at the plan's breaks when no event watches slip): (states at t_out
    reached, stop time, state at the stop, counters). jac: the Jacobian of f for the implicit methods;
    compiled: the ``memoryrhs.Phase`` whose kernel f and jac call (ODEPACK's loop then calls the kernel itself);
    odepack: LSODA's loop in ODEPACK on f (``solve``)."""
    tscale = T
    s_eval = np.clip(np.asarray(t_out, dtype=float) / tscale, t0 / tscale, T / tscale)
    s_eval, back = np.unique(s_eval, return_inverse=True)  # repeated times (e.g. a resample) solved once
    failed = f"ode:{method}: integration failed for law '{plan.law.name}'"
    # where the right-hand side jumps (a load-point velocity step) the integration restarts
    cuts = [b / tscale for b in plan.breaks if t0 < b < T] if event is None else []
    edges = [t0 / tscale] + cuts + [T / tscale]
    z0, parts, stats = np.asarray(y0, dtype=float) / scale, [], {"nfev": 0, "njev": 0, "nlu": 0}
    try:
        for k, (a, b) in enumerate(zip(edges[:-1], edges[1:])):
            last = k == len(edges) - 2
            inside = s_eval[(s_eval >= a) & ((s_eval <= b) if last else (s_eval < b))]
            Z, s_stop, z_stop, solver = solve(f, a, b, z0, method, inside, rtol, atol, event, -direction, failed, jac,
                                              compiled, odepack)
            parts.append(Z)
            for key in stats:
                stats[key] += int(getattr(solver, key))
            z0 = solver.y
    except FrictionLabError:
        raise
    except Exception as exc:  # a law raising inside the integrator
        raise SolverError(f"{failed}: {exc}") from exc
    if compiled is not None and compiled.bad:
        raise SolverError(f"{failed}: the compiled right-hand side was not finite or past its budget")
    Z = np.hstack(parts)
    Y = Z[:, back[back < Z.shape[1]]] * scale[:, None]  # a stop ends the samples reached
    t_stop = y_stop = None
    if s_stop is not None:
        t_stop = float(s_stop) * tscale
        y_stop = z_stop * scale
    info = {**stats, "method": method, "rtol": rtol, "atol": atol}
    return Y, t_stop, y_stop, info


