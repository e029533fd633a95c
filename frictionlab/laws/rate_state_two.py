"""Rate-and-state friction with two state variables (Ruina 1983; Gu, Rice, Ruina and Tse 1984):

mu = mu0 + a ln(V/V0) + b1 ln(V0 theta1/Dc1) + b2 ln(V0 theta2/Dc2), each state evolving by the aging or
the slip law with its own Dc. Steady state theta_i = Dc_i/|V|, mu_ss = mu0 + (a - b1 - b2) ln(|V|/V0);
b2 = 0 is the one-state law. The two (b, Dc) pairs are interchangeable: a fit may return them in
either order, and with b2 near 0 Dc2 is not determined."""
import numpy as np

from frictionlab.laws.rate_state import V0, V_FLOOR, RateState, aging_rate, slip_rate
from frictionlab.physics.law import ParamSpec, StateSpec


class RateStateTwo(RateState):
    """Base of the two-state laws (not registered itself): subclasses set ``evolve``, an aging or slip rate."""

    params = (
        RateState.params[0], RateState.params[1],
        ParamSpec("b1", "", 0.01, 0.0, 0.5, 0.01, "evolution effect of the first state"),
        ParamSpec("Dc1", "m", 1e-5, 1e-9, 1.0, 1e-5, "critical slip distance of the first state", display="um"),
        ParamSpec("b2", "", 0.005, 0.0, 0.5, 0.01, "evolution effect of the second state"),
        ParamSpec("Dc2", "m", 1e-4, 1e-9, 1.0, 1e-4, "critical slip distance of the second state", display="um"),
    )
    states = (StateSpec("theta1", "s", "steady", 1.0, "first state variable"),
              StateSpec("theta2", "s", "steady", 1.0, "second state variable"))

    def evolution(self, p, state):
        return sum(p[f"b{i}"] * np.log(V0 * np.maximum(state[f"theta{i}"], 1e-300) / p[f"Dc{i}"]) for i in (1, 2))

    def steady_state(self, p, c):
        V = np.maximum(np.abs(c.u), V_FLOOR)
        return {f"theta{i}": p[f"Dc{i}"] / V for i in (1, 2)}

    def rates(self, p, c):
        return {f"theta{i}": type(self).evolve(c.u, c.state[f"theta{i}"], p[f"Dc{i}"]) for i in (1, 2)}


class RateStateAging2(RateStateTwo):
    name = "rate-state-aging2"
    formula = ("mu = mu0 + a ln(V/V0) + sum_i b_i ln(V0 theta_i/Dc_i), V0 = 1 um/s, "
               "d theta_i/dt = 1 - V theta_i/Dc_i (i = 1, 2)")
    citation = "Ruina, J. Geophys. Res. 88, 10359 (1983); Dieterich (1979); " + RateState.citation
    evolve = staticmethod(aging_rate)


class RateStateSlip2(RateStateTwo):
    name = "rate-state-slip2"
    formula = ("mu = mu0 + a ln(V/V0) + sum_i b_i ln(V0 theta_i/Dc_i), V0 = 1 um/s, "
               "d theta_i/dt = -(V theta_i/Dc_i) ln(V theta_i/Dc_i) (i = 1, 2)")
    citation = "Ruina, J. Geophys. Res. 88, 10359 (1983); " + RateState.citation
    evolve = staticmethod(slip_rate)
