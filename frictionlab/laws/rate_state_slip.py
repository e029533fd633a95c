"""Rate-and-state friction with the slip (Ruina) evolution law: d theta/dt = -(|V| theta/Dc) ln(|V| theta/Dc).

The state changes only with slip (no healing in truly stationary contact)."""
from frictionlab.laws.rate_state import RateState, slip_rate


class RateStateSlip(RateState):
    name = "rate-state-slip"
    formula = "mu = mu0 + a ln(V/V0) + b ln(V0 theta/Dc), V0 = 1 um/s, d theta/dt = -(V theta/Dc) ln(V theta/Dc)"
    citation = "Ruina, J. Geophys. Res. 88, 10359 (1983); " + RateState.citation

    def rates(self, p, c):
        return {"theta": slip_rate(c.u, c.state["theta"], p["Dc"])}
