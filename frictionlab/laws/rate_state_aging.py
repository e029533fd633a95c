"""Rate-and-state friction with the aging (Dieterich) evolution law: d theta/dt = 1 - |V| theta / Dc.

The state grows as the time of stationary contact (healing in a hold as ln t)."""
from frictionlab.laws.rate_state import RateState, aging_rate


class RateStateAging(RateState):
    name = "rate-state-aging"
    formula = "mu = mu0 + a ln(V/V0) + b ln(V0 theta/Dc), V0 = 1 um/s, d theta/dt = 1 - V theta/Dc"
    citation = "Dieterich, J. Geophys. Res. 84, 2161 (1979); " + RateState.citation

    def rates(self, p, c):
        return {"theta": aging_rate(c.u, c.state["theta"], p["Dc"])}
