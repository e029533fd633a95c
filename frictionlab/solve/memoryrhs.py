"""The compiled right-hand side of a built-in law with memory, and its analytic Jacobian.

``Plan.derivatives`` evaluates a law with memory through the scene's models and the law's ``force`` and
``rates`` on arrays (about 55 us a call); a stiff law (LuGre's bristles relax in ~1e-7 s) takes thousands of
calls a solve, and the implicit methods then also difference the right-hand side for their Jacobian. For the
built-in laws with memory on the scenes below, ``phase`` gives the scaled right-hand side of a sliding phase
and its Jacobian in closed form, compiled by numba (``memory_kernel``, about 1 us a call):

  laws    LuGre, Dahl, rate-and-state aging and slip (laws/), by their class: a subclass may change any method;
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

from . import compiled
from .memory_codes import (COUPLED, DIRECTION, DRIVE, IL, ILOAD, INERTIA, ITH, IW, LAW, MASS, MAXCALLS, NC, NORMAL,
                           NORMAL_CONSTANT, NORMAL_HALF_SINE, NORMAL_PHI, NORMAL_TC, NORMAL_VALUE, RADIUS, SPIN,
                           STIFFNESS, STOP_T, TINY, TSCALE, CALLS, BAD, DAHL, LUGRE, RS_AGING, RS_SLIP)

#: The built-in laws with memory served here, by (module, class), with their code and parameter order.
LAWS = {("frictionlab.laws.lugre", "LuGre"): (LUGRE, ("mu_c", "mu_s", "vs", "sigma0", "sigma1", "sigma2")),
        ("frictionlab.laws.dahl", "Dahl"): (DAHL, ("mu_c", "sigma", "alpha")),
        ("frictionlab.laws.rate_state_aging", "RateStateAging"): (RS_AGING, ("mu0", "a", "b", "Dc")),
        ("frictionlab.laws.rate_state_slip", "RateStateSlip"): (RS_SLIP, ("mu0", "a", "b", "Dc"))}


def _normal(model):
    """(code, value or peak [N], phi [1/s], contact time [s]) of a normal-force model, or None."""
    from ..physics.scene import ConstantNormal, HalfSineNormal, WeightNormal

    if type(model) is HalfSineNormal:
        tc = float(model.contact_time)
        return NORMAL_HALF_SINE, float(model.peak), math.pi / tc, tc
    if type(model) in (ConstantNormal, WeightNormal):
        return NORMAL_CONSTANT, float(model.value), 0.0, 0.0
    return None


class Phase:
    """The kernel's arguments for one sliding phase: ``f(s, z)`` and ``jac(s, z)`` call it from Python; ``args``
    are what ``rhs(s, z, *args)`` and ``jac(s, z, *args)`` take (ODEPACK's loop calls them directly).
    ``C[CALLS]`` counts the calls; ``C[BAD]`` is 2 once they passed the cap (at ``stop_time``), 1 where a value
    was not finite (the kernel then returns NaN, and the phase is not to be trusted)."""

    def __init__(self, P, C, scale, V):
        from . import memory_kernel

        self.kernel = memory_kernel
        self.C = C
        self.args = (P, C, np.ascontiguousarray(scale, dtype=float), V)

    def f(self, s, z):
        return self.kernel.rhs(s, z, *self.args)

    def jac(self, s, z):
        return self.kernel.jac(s, z, *self.args)

    @property
    def calls(self) -> int:
        return int(self.C[CALLS])

    @property
    def bad(self) -> int:
        return int(self.C[BAD])

    @property
    def stop_time(self) -> float:
        """The time [s] at which the calls passed the cap."""
        return float(self.C[STOP_T])


def served(plan) -> bool:
    """Whether ``phase`` serves this plan's law and scene (numba aside)."""
    s = plan.scene
    return ((type(plan.law).__module__, type(plan.law).__name__) in LAWS and len(plan.law_states) == 1
            and "xi" not in plan.states and "x" not in plan.states and _normal(s.normal) is not None
            and (s.spring is None or s.spring.inertial))


def phase(plan, p, direction: float, vanishing: float, tscale: float, scale, max_calls: int) -> Phase | None:
    """The compiled phase of ``plan`` for law parameters p (SI): slip direction (0: none) and the slip held while
    a stage has not got its sign (``solvers.stick.vanishing_slip``), time scale [s] and state scales as
    ``solvers.ode`` scales the problem, at most ``max_calls`` calls; None where it does not serve the plan."""
    if not served(plan) or not compiled.available():
        return None
    s, law = plan.scene, plan.law
    code, names = LAWS[(type(law).__module__, type(law).__name__)]
    P = np.array([float(p[k]) for k in names])
    C = np.zeros(NC)
    C[LAW] = code
    C[IL] = plan.index(plan.law_states[0])
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
    return Phase(P, C, scale, V)
