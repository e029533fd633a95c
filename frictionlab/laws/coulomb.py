"""Coulomb friction: F = mu N, opposing slip."""
from frictionlab.physics.law import FrictionLaw, NormalAreaRateForm, ParamSpec, sign


class Coulomb(FrictionLaw):
    name = "coulomb"
    formula = "F = mu N sign(u)"
    citation = "Coulomb (1785); any tribology textbook"
    params = (ParamSpec("mu", "", 0.3, 0.0, 5.0, 0.3, "kinetic friction coefficient"),)
    requires = frozenset({"u", "N"})

    def force(self, p, c):
        return p["mu"] * c.N * sign(c.u)

    def form(self, p):
        return NormalAreaRateForm(a=p["mu"], c=0.0)
