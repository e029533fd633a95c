"""Dieterich-Ruina rate-and-state friction, shared by the one-state evolution laws (aging, slip, PRZ, Nagata).

mu = mu0 + a ln(V/V0) + b ln(V0 theta/Dc),  F = mu N sign(V). Evaluated in the regularized form
mu = a asinh(V/(2 V0) exp(psi/a)), psi = mu0 + b ln(V0 theta/Dc) (Rice and Ben-Zion 1996), which
equals the log form to relative exp(-2 mu/a) (1e-50 at mu = 0.6, a = 0.01) and stays finite
through V = 0. Steady state theta_ss = Dc/|V|, mu_ss = mu0 + (a - b) ln(|V|/V0).
V0 is a reference speed, not a parameter: mu0 and V0 enter only as mu0 - (a - b) ln V0, so fitting
both would be degenerate. It is fixed at 1 um/s (a common laboratory reference); mu0 is the steady
friction there. Software anchor: rsfmodel (Leeman et al., SciPy 2016).
"""
import numpy as np

from frictionlab.physics.law import FrictionLaw, ParamSpec, StateSpec

#: Reference slip speed V0 [m/s]: mu0 is the steady-state friction coefficient at this speed.
V0 = 1e-6

#: Slip speed [m/s] below which the steady state is taken at this speed (theta_ss = Dc/|V| is infinite at 0).
V_FLOOR = 1e-15


def asinh_exp(L):
    """asinh(exp(L)) without overflow, elementwise."""
    L = np.asarray(L, dtype=float)
    with np.errstate(over="ignore"):
        big = L + np.log1p(np.sqrt(1.0 + np.exp(-2.0 * np.maximum(L, 0.0))))
    return np.where(L > 0, big, np.arcsinh(np.exp(np.minimum(L, 0.0))))


def aging_rate(V, theta, Dc):
    """d theta/dt [-] of the aging (Dieterich) law, 1 - |V| theta / Dc (V [m/s], theta [s], Dc [m])."""
    return 1.0 - np.abs(V) * theta / Dc


def slip_rate(V, theta, Dc):
    """d theta/dt [-] of the slip (Ruina) law, -(|V| theta / Dc) ln(|V| theta / Dc), 0 at V = 0."""
    x = np.abs(V) * theta / Dc
    return -np.where(x > 0, x * np.log(np.where(x > 0, x, 1.0)), 0.0)


class RateState(FrictionLaw):
    """Base of the one-state rate-and-state laws (not registered itself): subclasses define ``rates``."""

    citation = ("Dieterich, J. Geophys. Res. 84 (1979); Ruina, J. Geophys. Res. 88 (1983); Marone, "
                "Annu. Rev. Earth Planet. Sci. 26 (1998)")
    params = (
        ParamSpec("mu0", "", 0.6, 0.0, 2.0, 0.1, "steady-state friction at V0 = 1 um/s"),
        ParamSpec("a", "", 0.01, 1e-5, 0.5, 0.01, "direct-effect parameter"),
        ParamSpec("b", "", 0.01, 0.0, 0.5, 0.01, "evolution-effect parameter"),
        ParamSpec("Dc", "m", 1e-5, 1e-9, 1.0, 1e-5, "critical slip distance", display="um"),
    )
    requires = frozenset({"u", "N"})
    states = (StateSpec("theta", "s", "steady", 1.0, "state variable (contact age)"),)
    # at V -> 0 the force turns over from -capacity to +capacity within ~1e-30 m/s: stick there instead
    jumps_at_zero_slip = True
    #: The steady state theta_ss = STEADY Dc / |V| (2 for the PRZ law, whose friction reads theta / (2 Dc)).
    STEADY = 1.0

    def evolution(self, p, state):
        """The evolution effect [-] b ln(V0 theta / (STEADY Dc)) of the states (0 at steady sliding at V0)."""
        return p["b"] * np.log(V0 * np.maximum(state["theta"], 1e-300) / (self.STEADY * p["Dc"]))

    def mu(self, p, V, state):
        """Friction coefficient [-] at slip speed V [m/s] and the states (by name, [s]), signed like V."""
        V = np.asarray(V, dtype=float)
        psi = p["mu0"] + self.evolution(p, state)
        with np.errstate(divide="ignore"):
            L = np.log(np.abs(V) / (2.0 * V0)) + psi / p["a"]
        return p["a"] * np.sign(V) * asinh_exp(L)

    def force(self, p, c):
        return c.N * self.mu(p, c.u, c.state)

    def steady_state(self, p, c):
        return {"theta": self.STEADY * p["Dc"] / np.maximum(np.abs(c.u), V_FLOOR)}
