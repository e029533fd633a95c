"""Dahl friction: the friction coefficient mu_d is a state that follows the slip like a stress-strain curve.

d mu_d/dt = sigma u |s|^alpha sign(s),  s = 1 - mu_d sign(u) / mu_c,  F = mu_d N. Normalized by N:
sigma [1/m] is the rest stiffness per unit normal force. Steady sliding: mu_d = mu_c sign(u) (Coulomb);
under periodic slip the force traces a closed hysteresis loop.
"""
import numpy as np

from frictionlab.physics.law import FrictionLaw, ParamSpec, StateSpec


class Dahl(FrictionLaw):
    name = "dahl"
    formula = "F = mu_d N, d mu_d/dt = sigma u |1 - mu_d sign(u)/mu_c|^alpha sign(...)"
    citation = "Dahl, 'A solid friction model', Aerospace Corp. TOR-0158(3107-18)-1 (1968)"
    params = (
        ParamSpec("mu_c", "", 0.3, 1e-6, 5.0, 0.3, "Coulomb friction coefficient (the loop's plateau)"),
        ParamSpec("sigma", "1/m", 1e5, 1.0, 1e12, 1e5, "rest stiffness per unit normal force"),
        ParamSpec("alpha", "", 1.0, 0.1, 5.0, 1.0, "shape exponent of the curve"),
    )
    requires = frozenset({"u", "N"})
    states = (StateSpec("mu_d", "", "steady", 0.3, "friction coefficient carried by the junctions"),)

    def force(self, p, c):
        return c.N * c.state["mu_d"]

    def rates(self, p, c):
        s = 1.0 - c.state["mu_d"] * np.sign(c.u) / p["mu_c"]
        return {"mu_d": p["sigma"] * c.u * np.abs(s) ** p["alpha"] * np.sign(s)}

    def steady_state(self, p, c):
        return {"mu_d": p["mu_c"] * np.sign(c.u)}
