"""Wear law of the seed paper, eq (3): F = lambda A u."""
from frictionlab.physics.law import AreaSlipForm, FrictionLaw, ParamSpec


class Wear(FrictionLaw):
    name = "wear"
    formula = "F = lam A u"
    citation = "Arakawa, Sci. Rep. 7, 2017 ('An analytical model of dynamic sliding friction during impact'), eq (3)"
    params = (ParamSpec("lam", "Pa s/m", 1e6, 0.0, 1e13, 1e6, "wear-related friction parameter lambda"),)
    requires = frozenset({"u", "A"})

    def force(self, p, c):
        return p["lam"] * c.A * c.u

    def form(self, p):
        return AreaSlipForm(k=p["lam"])
