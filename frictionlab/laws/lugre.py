"""LuGre friction: bristles of deflection z [m] with the Stribeck curve as their steady state.

dz/dt = u - sigma0 |u| z / g(u),  F = N (sigma0 z + sigma1 dz/dt + sigma2 u),  g the Stribeck curve
(laws/stribeck.py). Normalized by the normal force N: sigma0 [1/m], sigma1 and sigma2 [s/m].
At steady sliding z = g(u) sign(u) / sigma0, so F = N (g(u) sign(u) + sigma2 u): the Stribeck law.
The bristles relax in g / (sigma0 |u|) ~ 1e-7 s at 10 m/s: a stiff problem (LSODA switches to BDF).
"""
import numpy as np
from frictionlab.laws.stribeck import Stribeck, stribeck_curve

from frictionlab.physics.law import FrictionLaw, ParamSpec, StateSpec


class LuGre(FrictionLaw):
    name = "lugre"
    formula = "F = N (sigma0 z + sigma1 dz/dt + sigma2 u), dz/dt = u - sigma0 |u| z / g(u)"
    citation = "Canudas de Wit, Olsson, Astrom and Lischinsky, IEEE Trans. Autom. Control 40, 419 (1995)"
    params = Stribeck.params[:3] + (
        ParamSpec("sigma0", "1/m", 1e5, 1.0, 1e12, 1e5, "bristle stiffness per unit normal force"),
        ParamSpec("sigma1", "s/m", 0.0, 0.0, 1e6, 1e-2, "bristle damping per unit normal force"),
        Stribeck.params[3],
    )
    requires = frozenset({"u", "N"})
    states = (StateSpec("z", "m", "steady", 1e-6, "mean bristle deflection"),)

    def _dzdt(self, p, c):
        return c.u - p["sigma0"] * np.abs(c.u) * c.state["z"] / stribeck_curve(p, c.u)

    def force(self, p, c):
        return c.N * (p["sigma0"] * c.state["z"] + p["sigma1"] * self._dzdt(p, c) + p["sigma2"] * c.u)

    def rates(self, p, c):
        return {"z": self._dzdt(p, c)}

    def steady_state(self, p, c):
        return {"z": stribeck_curve(p, c.u) * np.sign(c.u) / p["sigma0"]}
