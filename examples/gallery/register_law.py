r"""# Registering a law, and ranking it

A law of your own is a small class: its parameters with SI units, bounds and a typical scale, what it needs
(slip velocity $u$, normal force $N$, area $A$, ...) and its force. Registered, it is fitted, ranked and
reported like the built-in laws. Here a velocity-weakening law,
$F = N\,\big(\mu_k + (\mu_s - \mu_k)\, e^{-|u|/v_s}\big) \operatorname{sign}(u)$, joins the comparison on a
lubricated incline (`incline-oil-a100`, *synthetic*, drawn from Couette friction with a recorded truth).
"""

# %%
# The law, registered by the decorator.
import numpy as np

import frictionlab as fl
from frictionlab import FrictionLaw, ParamSpec, register_law


@register_law
class ExpStribeck(FrictionLaw):
    """Velocity-weakening friction: mu falls from mu_s at rest to mu_k over a speed v_s."""

    name = "exp-stribeck"
    formula = "F = N (mu_k + (mu_s - mu_k) exp(-|u| / v_s)) sign(u)"
    citation = "R. Stribeck, Z. VDI 46 (1902)"
    params = (
        # name, SI unit, default, lower, upper, typical scale, description
        ParamSpec("mu_s", "", 0.4, 0.0, 5.0, 0.3, "static friction coefficient"),
        ParamSpec("mu_k", "", 0.2, 0.0, 5.0, 0.3, "kinetic friction coefficient"),
        ParamSpec("v_s", "m/s", 0.1, 1e-6, 100.0, 0.1, "Stribeck velocity"),
    )
    requires = frozenset({"u", "N"})

    def force(self, p, c):
        """Friction force [N]; p holds SI parameter values, c the contact arrays."""
        mu = p["mu_k"] + (p["mu_s"] - p["mu_k"]) * np.exp(-np.abs(c.u) / p["v_s"])
        return mu * c.N * np.sign(c.u)


print("exp-stribeck" in fl.available_laws(), fl.get_law("exp-stribeck").formula)

# %%
# Rank it against Coulomb and the lubricated law. What the table shows: the candidates in AIC order, whether
# each fits and its Akaike weight among those that fit. The data were drawn from Couette friction, so a
# law that levels the velocity off fits them and Coulomb, whose velocity only grows, does not.
c = fl.compare(laws=["exp-stribeck", "couette", "coulomb"], datasets=["incline-oil-a100"], equivalence=False)
table = c.to_dataframe()
print(table[table.dataset == "incline-oil-a100"][["candidate", "rank", "fits", "delta_aic", "akaike_weight"]]
      .to_string(index=False))

# %%
# The new law's fit, as the comparison made it, drawn as any other: velocity against time above, residuals below.
fit = next(f for f in c.fits if f.law == "exp-stribeck")
fit.plot()
