"""Drive a solution through sliding and stuck phases; each solver supplies the sliding phase.

A sliding-phase function has the signature
    slide(plan, p, t0, y0, direction, t_out) -> (Y_out, t_stop, y_stop, info)
where Y_out holds the states at the times t_out (all >= t0, only those reached), t_stop is
the time slip reached zero (None if it did not before t_out[-1] or the end), y_stop the state there.

A law with memory (unless it declares ``jumps_at_zero_slip``), and any law on a spring-slider, is
integrated in one phase through zero slip (direction 0: no stick event; ``Plan.continuous``): a
law's internal state carries what static friction there is (LuGre's bristles), and a spring's
drive changes with the state, which the stuck-phase formulas of ``stick`` do not model. While
stuck, a law's internal states are held.
"""
from __future__ import annotations

import numpy as np

from ...core.errors import SolverError
from ...physics.trajectory import Trajectory
from . import stick

MAX_SEGMENTS = 200
#: Chatter seen early: CHATTER_CYCLES slides in a row, each begun by a stuck phase that broke away at once, that
#: left the states as they were (to CHATTER_RTOL) and covered so little time that the segments left could not
#: reach the end at CHATTER_MARGIN times that pace: the cycle repeats itself and the solve would end in the
#: chatter error after MAX_SEGMENTS segments anyway, only later.
CHATTER_CYCLES, CHATTER_RTOL, CHATTER_MARGIN = 8, 1e-6, 1e3
COUNTERS = ("nfev", "njev", "nlu")  # solver statistics summed over segments


def run(plan, p, t_eval, slide, solver_name: str) -> Trajectory:
    t_eval = np.asarray(t_eval, dtype=float)
    Y, F, sliding, dirs, info, stick_time = _phases(plan, p, t_eval, slide, solver_name)
    return _trajectory(plan, p, t_eval, Y, F, sliding, dirs, info, stick_time, solver_name)


def _start(plan, p, T, y0):
    """The first phase ('slide' or 'stuck') and its slip direction."""
    u_start = float(plan.rigid_slip(y0))
    direction = float(np.sign(u_start))
    if plan.continuous:
        return "slide", 0.0
    if "xi" in plan.states or u_start != 0.0:
        return "slide", direction
    tb = stick.breakaway(plan, p, 0.0, max(T, 0.0), y0, 0.0)
    return ("slide" if tb == 0.0 else "stuck"), stick.hold_direction(plan, 0.0)


def _phases(plan, p, t_eval, slide, solver_name):
    """Sliding and stuck phases in turn over t_eval: (states Y, stuck force F, sliding mask, slip direction
    of each sample's sliding phase, info, first stick time or None)."""
    n, T = t_eval.size, float(t_eval[-1])
    Y = np.empty((len(plan.states), n))
    F = np.empty(n)
    sliding = np.zeros(n, dtype=bool)
    dirs = np.zeros(n)  # slip direction of the sliding phase each sample belongs to
    done = np.zeros(n, dtype=bool)
    t0, y0 = 0.0, plan.initial_state(p)
    info: dict = {"nfev": 0, "segments": 0}
    stick_time = None
    phase, direction = _start(plan, p, T, y0)
    last_direction = direction or 1.0
    cycles: list = []  # (time, state) where each slide began after a stuck phase that broke away at once
    while True:
        info["segments"] += 1
        if info["segments"] > MAX_SEGMENTS or _chattering(cycles, T, MAX_SEGMENTS - info["segments"]):
            raise SolverError(f"{solver_name}: slip changed between sliding and sticking more than "
                              f"{MAX_SEGMENTS} times (chatter); the law is not suited to this scene")
        todo = (~done) & (t_eval >= t0)
        if phase == "slide":
            Ys, t_stop, y_stop, seg = slide(plan, p, t0, y0, direction, t_eval[todo])
            for k, v in seg.items():  # counters add up over segments; settings are kept as given
                info[k] = info.get(k, 0) + v if k in COUNTERS else v
            idx = np.nonzero(todo)[0][: Ys.shape[1]]
            Y[:, idx] = Ys
            sliding[idx] = True
            dirs[idx] = direction
            done[idx] = True
            if t_stop is not None and stick_time is None:
                stick_time = t_stop
            if t_stop is None or t_stop >= T:
                break
            last_direction = direction
            t0, y0 = t_stop, _zero_slip(plan, y_stop)
            phase = "stuck"
        else:
            tb = stick.breakaway(plan, p, t0, T, y0, last_direction)
            idx = np.nonzero(todo & (t_eval <= (T if tb is None else tb)))[0]
            Y[:, idx], F[idx] = stick.stuck_states(plan, t_eval[idx], t0, y0)
            done[idx] = True
            if tb is None:
                break
            ys, _ = stick.stuck_states(plan, np.array([tb]), t0, y0)
            cycles = (cycles + [(tb, ys[:, 0])])[-CHATTER_CYCLES - 1:] if tb == t0 else []
            t0, y0 = tb, ys[:, 0]
            direction = stick.hold_direction(plan, last_direction)
            phase = "slide"
    if not done.all():
        raise SolverError(f"{solver_name}: solution ended at t = {t0:g} s before the last requested time {T:g} s")
    return Y, F, sliding, dirs, info, stick_time


def _chattering(cycles, T: float, segments_left: int) -> bool:
    """Whether the last CHATTER_CYCLES stick-slip cycles (``_phases``) repeat themselves too fast to reach T."""
    if len(cycles) <= CHATTER_CYCLES:
        return False
    (t_old, y_old), (t_now, y_now) = cycles[-CHATTER_CYCLES - 1], cycles[-1]
    pace = (t_now - t_old) / CHATTER_CYCLES  # time a cycle (two segments) covers
    return (CHATTER_MARGIN * pace * max(segments_left, 0) / 2 < T - t_now
            and bool(np.all(np.abs(y_now - y_old) <= CHATTER_RTOL * np.abs(y_old))))


def _trajectory(plan, p, t_eval, Y, F, sliding, dirs, info, stick_time, solver_name):
    """Slip, force and contact on t_eval from the phases' states, checked finite, as a Trajectory."""
    n = t_eval.size
    compliant = "xi" in plan.states
    u = np.empty(n)
    if compliant:  # the force on the body is the spring's and damper's, also while the patch sticks
        for i in np.nonzero(sliding)[0]:
            F[i], u[i] = plan.patch_force(p, t_eval[i], Y[:, i])
    else:
        u[:] = plan.rigid_slip(Y)
        # within a sliding phase slip keeps its sign: rounding (1e-15 m/s) must not flip it
        held = sliding & (dirs != 0)
        u[held] = dirs[held] * np.maximum(dirs[held] * u[held], 0.0)
    u[~sliding] = 0.0
    c = plan.contact(t_eval, Y, u)
    if sliding.any() and not compliant:
        F[sliding] = plan.law.evaluate(p, c if sliding.all() else _subset(c, sliding))
    A = c.A if c.A is not None else (plan.area(t_eval, Y, u)[0] if plan.needs_area else None)
    omega = Y[plan.index("omega")] if plan.has_spin else np.zeros(n)
    theta = Y[plan.index("theta")] if plan.has_spin else np.zeros(n)
    for name, arr in (("u", u), ("v", Y[0]), ("omega", omega), ("theta", theta), ("force", F)):
        if not np.isfinite(arr).all():
            raise SolverError(f"{solver_name}: {name} became NaN or infinite for law '{plan.law.name}' with {dict(p)}")
    load = None
    if plan.scene.spring is not None:  # with a mass the spring's own state; quasi-static: spring = friction
        load = Y[plan.index("load")].copy() if "load" in plan.states else F / plan.scene.normal(t_eval)
    return Trajectory(t=t_eval, u=u, v=Y[0].copy(), omega=omega, theta=theta, force=F, A=A, N=c.N, load=load,
                      solver=solver_name, law=plan.law.name, stick_time=stick_time, info=info,
                      law_states={n: Y[plan.index(k)].copy() for n, k in zip(plan.law.state_names, plan.law_states)})


def _subset(c, mask):
    import attrs

    state = None if c.state is None else {k: v[mask] for k, v in c.state.items()}
    return attrs.evolve(c, state=state, **{k: (getattr(c, k)[mask] if getattr(c, k) is not None else None)
                                           for k in ("t", "u", "N", "A", "dAdt")})


def _zero_slip(plan, y):
    """Set slip to exactly zero at a stick event."""
    y = np.array(y, dtype=float)
    y[0] = plan.scene.radius * y[plan.index("omega")] if plan.coupled else 0.0
    return y
