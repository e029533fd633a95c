"""Stribeck friction (memoryless): the friction coefficient falls from a static to a Coulomb level with
slip speed, plus a viscous term. F = N [g(u) sign(u) + sigma2 u], g(u) = mu_c + (mu_s - mu_c) exp(-(u/vs)^2)."""
import numpy as np

from frictionlab.physics.law import FrictionLaw, ParamSpec, sign


def stribeck_curve(p, u):
    """g(u) = mu_c + (mu_s - mu_c) exp(-(u/vs)^2) [-], the Stribeck curve (shared with LuGre)."""
    return p["mu_c"] + (p["mu_s"] - p["mu_c"]) * np.exp(-(np.asarray(u) / p["vs"]) ** 2)


class Stribeck(FrictionLaw):
    name = "stribeck"
    formula = "F = N [(mu_c + (mu_s - mu_c) exp(-(u/vs)^2)) sign(u) + sigma2 u]"
    citation = "Stribeck, Z. VDI 46 (1902); in this form Armstrong-Helouvry, Dupont and Canudas de Wit, Automatica 30 (1994)"
    params = (
        ParamSpec("mu_c", "", 0.3, 1e-6, 5.0, 0.3, "Coulomb (kinetic) friction coefficient"),
        ParamSpec("mu_s", "", 0.5, 0.0, 5.0, 0.3, "static friction coefficient"),
        ParamSpec("vs", "m/s", 1e-3, 1e-9, 1e3, 1e-3, "Stribeck velocity"),
        ParamSpec("sigma2", "s/m", 0.0, 0.0, 1e6, 1e-2, "viscous friction per unit normal force"),
    )
    requires = frozenset({"u", "N"})

    def force(self, p, c):
        return c.N * (stribeck_curve(p, c.u) * sign(c.u) + p["sigma2"] * c.u)
