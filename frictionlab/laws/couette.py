"""Lubricated Couette law: F = tau A with tau = (eta / h) u.

Only eta/h enters the force: from motion alone eta and h are not separately
identifiable. Fix one (a dataset's ``[fixed]`` table usually fixes eta) to fit the other.
"""
from frictionlab.physics.law import AreaSlipForm, FrictionLaw, ParamSpec


class Couette(FrictionLaw):
    name = "couette"
    formula = "F = (eta / h) A u"
    citation = "Arakawa, Tribol. Int. (2016), PU rubber on oiled PMMA incline"
    params = (
        ParamSpec("eta", "Pa s", 0.1, 1e-6, 1e6, 0.1, "lubricant dynamic viscosity"),
        ParamSpec("h", "m", 1e-6, 1e-12, 1.0, 1e-6, "lubricant film thickness", display="um"),
    )
    requires = frozenset({"u", "A"})
    ratio_only = (("eta", "h"),)

    def force(self, p, c):
        return (p["eta"] / p["h"]) * c.A * c.u

    def form(self, p):
        return AreaSlipForm(k=p["eta"] / p["h"])
