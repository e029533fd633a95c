"""A law driven by a prescribed slip history: its internal states and force, no body dynamics.

``respond(law, params, t, u, N=1.0)`` integrates the law's states along slip u(t) (a callable
[m/s]) with solve_ivp (LSODA) and returns (force [N] at t, states by name at t). This is how a
law's own behaviour is examined: LuGre's steady-state curve, Dahl's hysteresis loop, healing.
"""
from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING

import numpy as np
from scipy.integrate import solve_ivp

from ...core.errors import SolverError
from ...physics.law import Contact
from ...physics.registry import get_law

if TYPE_CHECKING:  # annotations only
    from ...physics.law import FrictionLaw


def respond(law: str | FrictionLaw, params: Mapping[str, float], t: np.ndarray,
            u: Callable[[np.ndarray], np.ndarray], N: float = 1.0, A: float | None = None,
            rtol: float = 1e-10) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Force [N] and internal states along the slip history u(t) [m/s] at times t [s] (t[0] is the start).

    The states start from their declared initial values (``steady`` ones at u(t[0])); N [N] and
    A [m^2] are held constant, dA/dt = 0.
    """
    law = get_law(law)
    if "dmudt" in law.requires:
        raise SolverError(f"law '{law.name}' reads d mu/dt (dmudt), which a prescribed slip history does not supply; "
                          "simulate it on a spring-slider")
    p = law.resolve(params)
    t = np.asarray(t, dtype=float)

    def contact(tt, state=None):
        tt = np.atleast_1d(tt)
        return Contact(t=tt, u=np.asarray(u(tt), dtype=float), N=np.full(tt.shape, float(N)),
                       A=None if A is None else np.full(tt.shape, float(A)), dAdt=np.zeros(tt.shape), state=state)

    names = law.state_names
    init = law.initial_states(p, contact(t[:1]))
    scales = np.array([s.scale for s in law.states])
    z0 = np.array([init[n][0] for n in names]) / scales

    def f(s, z):
        c = contact(s, {n: np.array([z[i] * scales[i]]) for i, n in enumerate(names)})
        r = law.evaluate_rates(p, c)
        return np.array([r[n][0] for n in names]) / scales

    if names:
        sol = solve_ivp(f, (t[0], t[-1]), z0, method="LSODA", t_eval=t, rtol=rtol, atol=rtol)
        if sol.status == -1:
            raise SolverError(f"law '{law.name}' under prescribed slip: {sol.message}")
        states = {n: sol.y[i] * scales[i] for i, n in enumerate(names)}
    else:
        states = {}
    return law.evaluate(p, contact(t, states or None)), states
