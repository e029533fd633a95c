"""Rate-and-state friction with the slip (Ruina) evolution law: d theta/dt = -(|V| theta/Dc) ln(|V| theta/Dc).

The state changes only with slip (no healing in truly stationary contact)."""
import numpy as np
from frictionlab.laws.rate_state import RateState


class RateStateSlip(RateState):
    name = "rate-state-slip"
    formula = "mu = mu0 + a ln(V/V0) + b ln(V0 theta/Dc), V0 = 1 um/s, d theta/dt = -(V theta/Dc) ln(V theta/Dc)"
    citation = "Ruina, J. Geophys. Res. 88, 10359 (1983); " + RateState.citation

    def rates(self, p, c):
        x = np.abs(c.u) * c.state["theta"] / p["Dc"]
        return {"theta": -np.where(x > 0, x * np.log(np.where(x > 0, x, 1.0)), 0.0)}
