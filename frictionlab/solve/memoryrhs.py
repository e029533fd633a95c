"""The compiled right-hand side of a built-in law with memory, and its analytic Jacobian.

``Plan.derivatives`` evaluates a law with memory through the scene's models and the law's ``force`` and
``rates`` on arrays (about 55 us a call); a stiff law (LuGre's bristles relax in ~1e-7 s) takes thousands of
calls a solve, and the implicit methods then also difference the right-hand side for their Jacobian. For the
built-in laws with memory on the scenes below, ``phase`` gives the scaled right-hand side of a sliding phase
and its Jacobian in closed form, compiled by numba (``memory_kernel``, about 1 us a call):

  laws    LuGre, Dahl, rate-and-state aging, slip and PRZ (laws/), by their class: a subclass may change any method;
  scenes  rigid impact or incline (states v, optionally omega and theta with spin and slip coupling; normal
          force half-sine, weight or constant), and the spring-slider with a mass (states v and load; constant
          normal force). The quasi-static spring-slider (its slip rate implicit) is not served here.

The formulas are the laws' own, with their products in the same order, so the derivatives agree with
``Plan.derivatives`` to rounding (tests/test_memoryrhs.py checks them, the Jacobian against central
differences, and solves and fits against the general path). Where a value is not finite the kernel says so
and the solver reruns the phase on the general path, which raises the law's one-line error or goes on.
Anything else, and a machine where numba does not import, takes the general path.
"""
from __future__ import annotations

import math

import numpy as np

from .memory_codes import (BAD, CALLS, COUPLED, DAHL, DAHL_SLID, DIRECTION, DRIVE, IL, ILOAD, INERTIA, ITH, IW, LAW,
                           LUGRE, MASS, MAXCALLS, NC, NORMAL, NORMAL_CONSTANT, NORMAL_HALF_SINE, NORMAL_PHI, NORMAL_TC,
                           NORMAL_VALUE, RADIUS, RS_AGING, RS_PRZ, RS_SLIP, S0, SENSE, SPIN, STIFFNESS, STOP_T, STRICT, TINY, TSCALE)

#: The built-in laws with memory served here, by (module, class), with their code and parameter order.
LAWS = {("frictionlab.laws.lugre", "LuGre"): (LUGRE, ("mu_c", "mu_s", "vs", "sigma0", "sigma1", "sigma2")),
        ("frictionlab.laws.dahl", "Dahl"): (DAHL, ("mu_c", "sigma", "alpha")),
        ("frictionlab.laws.rate_state_aging", "RateStateAging"): (RS_AGING, ("mu0", "a", "b", "Dc")),
        ("frictionlab.laws.rate_state_slip", "RateStateSlip"): (RS_SLIP, ("mu0", "a", "b", "Dc")),
        ("frictionlab.laws.rate_state_prz", "RateStatePRZ"): (RS_PRZ, ("mu0", "a", "b", "Dc"))}


def _normal(model):
    """(code, value or peak [N], phi [1/s], contact time [s]) of a normal-force model, or None."""
    from ..physics.scene import ConstantNormal, HalfSineNormal, WeightNormal

    if type(model) is HalfSineNormal:
        tc = float(model.contact_time)
        return NORMAL_HALF_SINE, float(model.peak), math.pi / tc, tc
    if type(model) in (ConstantNormal, WeightNormal):
        return NORMAL_CONSTANT, float(model.value), 0.0, 0.0
    return None


#: The most turns of the slip a Dahl phase follows in the slid form before it is integrated in mu_d instead. The
#: slid form pays where the slip keeps its sense (mu_d near +-mu_c, where |s|^alpha is not smooth); a slip that
#: keeps turning is an oscillation about rest, mu_d well inside the bounds, where mu_d's own rate is smooth and
#: one phase in ODEPACK costs less than a chain of phases stepped one turn at a time.
MAX_TURNS = 8


class Phase:
    """The kernel's arguments for one sliding phase: ``f(s, z)`` and ``jac(s, z)`` call it from Python; ``args``
    are what ``rhs(s, z, *args)`` and ``jac(s, z, *args)`` take (ODEPACK's loop calls them directly).
    ``C[CALLS]`` counts the calls; ``C[BAD]`` says why the phase is not to be trusted (memory_codes: a value not
    finite, the calls past the cap at ``stop_time``, Dahl's slip turned). ``y0`` and ``scale``: the phase's
    initial state and state scales as integrated (Dahl's slid form integrates the slip since the phase began in
    place of mu_d); ``states(Y)`` gives back the plan's states."""

    def __init__(self, kernel, P, C, y0, scale, V):
        self.kernel = kernel
        self.C, self.P = C, P
        self.y0, self.scale = y0, np.ascontiguousarray(scale, dtype=float)
        self.args = (P, C, self.scale, V)

    def f(self, s, z):
        return self.kernel.rhs(s, z, *self.args)

    def jac(self, s, z):
        return self.kernel.jac(s, z, *self.args)

    @property
    def bad(self) -> int:
        return int(self.C[BAD])

    @property
    def stop_time(self) -> float:
        """The time [s] at which the calls passed the cap."""
        return float(self.C[STOP_T])

    def states(self, Y):
        """The plan's states from the integrated ones (n_states, k) (a copy where they differ), or None for None."""
        if Y is None or self.C[LAW] != DAHL_SLID:
            return Y
        Y = np.array(Y, dtype=float)
        il = int(self.C[IL])
        Y[il] = self.kernel.dahl_mu(self.P, self.C[S0], self.C[SENSE], np.ascontiguousarray(Y[il]).ravel()).reshape(
            Y[il].shape)
        return Y


_KERNEL: list = []  # [the kernel module, or None where numba does not import], once a process asked


def _kernel():
    """``memory_kernel`` (imports numba; compiles or loads the kernel on first use), or None where that fails."""
    if not _KERNEL:
        try:
            from . import memory_kernel
        except Exception:  # numba's import fails in many ways (solve.compiled warns of it); none may stop a solve
            memory_kernel = None
        _KERNEL.append(memory_kernel)
    return _KERNEL[0]


def available() -> bool:
    """Whether the compiled path can run here (numba imports)."""
    return _kernel() is not None


def served(plan) -> bool:
    """Whether ``phase`` serves this plan's law and scene (numba aside)."""
    s = plan.scene
    return ((type(plan.law).__module__, type(plan.law).__name__) in LAWS and len(plan.law_states) == 1
            and "xi" not in plan.states and "x" not in plan.states and _normal(s.normal) is not None
            and (s.spring is None or s.spring.inertial))


def phase(plan, p, direction: float, vanishing: float, tscale: float, y0, scale, max_calls: int,
          slid: bool = True, sense: float | None = None) -> Phase | None:
    """The compiled phase of ``plan`` for law parameters p (SI) from the state y0: slip direction (0: none) and the
    slip held while a stage has not got its sign (``solvers.stick.vanishing_slip``), time scale [s] and state
    scales as ``solvers.ode`` scales the problem, at most ``max_calls`` calls; None where it does not serve the
    plan. slid: Dahl in its slid form (``memory_kernel.law``) where the phase's slip has a sense; sense: that
    sense, given (then the slip may turn: an event ends the phase there), or None: the initial slip's (or the
    drive's), and the kernel stops where the slip turns."""
    kernel = _kernel() if served(plan) else None
    if kernel is None:
        return None
    s, law = plan.scene, plan.law
    code, names = LAWS[(type(law).__module__, type(law).__name__)]
    P = np.array([float(p[k]) for k in names])
    C = np.zeros(NC)
    il = plan.index(plan.law_states[0])
    C[IL] = il
    spin = plan.has_spin
    if spin:
        C[IW], C[ITH] = plan.index("omega"), plan.index("theta")
    C[ILOAD] = plan.index("load") if "load" in plan.states else -1
    C[COUPLED], C[SPIN] = float(plan.coupled), float(spin)
    C[RADIUS] = float(s.radius) if spin or plan.coupled else 0.0
    C[INERTIA] = float(s.inertia) if spin else 1.0
    C[MASS] = float(s.spring.mass) if s.spring is not None else float(s.mass)
    C[DRIVE] = float(plan.drive)
    C[NORMAL], C[NORMAL_VALUE], C[NORMAL_PHI], C[NORMAL_TC] = _normal(s.normal)
    C[DIRECTION], C[TINY] = float(direction), float(direction) * float(vanishing)
    C[TSCALE], C[MAXCALLS] = float(tscale), float(max_calls)
    if s.spring is not None:
        C[STIFFNESS] = float(s.spring.stiffness)
        V = np.array([s.spring.times, s.spring.velocities], dtype=float)
    else:
        V = np.zeros((2, 1))
    y0 = np.array(y0, dtype=float)
    scale = np.array(scale, dtype=float)
    C[STRICT] = float(sense is None)
    if sense is None:
        u0 = float(plan.rigid_slip(y0))
        sense = np.sign(u0) if u0 != 0.0 else (np.sign(plan.drive) if s.spring is None else 0.0)
    if code == DAHL and slid and sense != 0.0:  # integrate the slip since the phase began in place of mu_d
        code = DAHL_SLID
        C[SENSE] = sense
        C[S0] = 1.0 - y0[il] * sense / P[0]
        y0[il] = 0.0
        # the slip over which s relaxes, mu_c / sigma, or the distance slid where that is shorter
        scale[il] = max(min(float(scale[0]) * float(tscale), P[0] / P[1]), 1e-300)
    C[LAW] = code
    return Phase(kernel, P, C, y0, scale, V)
