"""Empirical area-rate law: F = mu N + mu eta' dA/dt, opposing slip.

While the contact unloads (dA/dt < 0) the second term is negative; if it outweighs
mu N, F has the sign opposite to the slip and the law pushes the body along it.
"""
from frictionlab.physics.law import FrictionLaw, NormalAreaRateForm, ParamSpec, sign


class AreaRate(FrictionLaw):
    name = "area-rate"
    formula = "F = (mu N + mu eta' dA/dt) sign(u)"
    citation = "Arakawa, Appl. Phys. Lett. 104, 241603 (2014)"
    params = (
        ParamSpec("mu", "", 0.3, 0.0, 5.0, 0.3, "kinetic friction coefficient"),
        ParamSpec("eta_prime", "N s/m^2", 0.0, -1e12, 1e12, 1e4,
                  "surface-condition factor multiplying the contact-area rate"),
    )
    requires = frozenset({"u", "N", "dAdt"})

    def force(self, p, c):
        return p["mu"] * (c.N + p["eta_prime"] * c.dAdt) * sign(c.u)

    def form(self, p):
        return NormalAreaRateForm(a=p["mu"], c=p["mu"] * p["eta_prime"])
