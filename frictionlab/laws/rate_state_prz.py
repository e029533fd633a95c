"""Rate-and-state friction with the PRZ evolution law (Perrin, Rice and Zheng 1995):
d theta/dt = 1 - (|V| theta / (2 Dc))^2, friction mu0 + a ln(V/V0) + b ln(V0 theta / (2 Dc)).

Like the aging law it heals in stationary contact (theta grows as t); like the slip law it answers velocity
steps up and down nearly symmetrically. Steady state theta_ss = 2 Dc / |V|, mu_ss = mu0 + (a - b) ln(|V|/V0)."""
from frictionlab.laws.rate_state import RateState


class RateStatePRZ(RateState):
    name = "rate-state-prz"
    formula = "mu = mu0 + a ln(V/V0) + b ln(V0 theta/(2 Dc)), V0 = 1 um/s, d theta/dt = 1 - (V theta/(2 Dc))^2"
    citation = "Perrin, Rice and Zheng, J. Mech. Phys. Solids 43, 1461 (1995); " + RateState.citation
    STEADY = 2.0

    def rates(self, p, c):
        x = c.u * c.state["theta"] / (2.0 * p["Dc"])
        return {"theta": 1.0 - x * x}
