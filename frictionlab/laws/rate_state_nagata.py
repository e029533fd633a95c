"""Rate-and-state friction with Nagata's evolution law (Nagata, Nakatani and Yoshida 2012):
d theta/dt = 1 - |V| theta / Dc - (c / b) theta d mu/dt.

The aging law with a term in the friction's own rate: a rising shear stress weakens the contact (c about 2
in Nagata's experiments); c = 0 is the aging law. The law requires "dmudt", which a spring-slider supplies
(its load rate k (V_lp - V)); b is kept above 1e-5 (c / b enters the rate)."""
from frictionlab.laws.rate_state import RateState, aging_rate
from frictionlab.physics.law import ParamSpec


class RateStateNagata(RateState):
    name = "rate-state-nagata"
    formula = ("mu = mu0 + a ln(V/V0) + b ln(V0 theta/Dc), V0 = 1 um/s, "
               "d theta/dt = 1 - V theta/Dc - (c/b) theta dmu/dt")
    citation = "Nagata, Nakatani and Yoshida, J. Geophys. Res. 117, B02314 (2012); " + RateState.citation
    params = (RateState.params[0], RateState.params[1],
              ParamSpec("b", "", 0.01, 1e-5, 0.5, 0.01, "evolution-effect parameter"),
              RateState.params[3],
              ParamSpec("c", "", 2.0, 0.0, 20.0, 1.0, "stress-weakening of the state (0: the aging law)"))
    requires = frozenset({"u", "N", "dmudt"})

    def rates(self, p, c):
        theta = c.state["theta"]
        return {"theta": aging_rate(c.u, theta, p["Dc"]) - (p["c"] / p["b"]) * theta * c.dmudt}
