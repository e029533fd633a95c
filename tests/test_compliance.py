"""Tangential compliance: a massless contact patch tied to the ball by a spring k and damper c.

Maw, Barber and Fawcett (1976): with tangential compliance the contact point of an obliquely
impacting ball can reverse its tangential velocity before the end of contact, and the spin
falls after a peak; a rigid model cannot do either (it slides, then rolls at 5 u0 / 7).
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from frictionlab import Scene, get_law, make_plan, simulate
from frictionlab.core.errors import SceneError, SolverError
from frictionlab.physics.scene import Compliance, HalfSineArea, HalfSineNormal

# A golf ball striking a rigid plate at 30 m/s, 30 deg from the normal.
M, R, TC = 0.0459, 0.02135, 450e-6
V, INC, E = 30.0, math.radians(30), 0.75
VT, VN = V * math.sin(INC), V * math.cos(INC)
MEFF = 2 * M / 7  # effective tangential mass of a solid sphere's contact point, 1/kappa
K = 2e6  # tangential stiffness [N/m]: half a tangential oscillation, pi sqrt(MEFF / K) = 256 us < t_c
C = 2 * 0.05 * math.sqrt(K * MEFF)  # 5 % of critical damping [N s/m]
MU = 0.35


def golf(compliant=True, k=K, c=C, duration=TC):
    effects = {"spin", "slip-coupling"} | ({"compliance"} if compliant else set())
    return Scene(kind="impact", mass=M, u0=VT, duration=duration, radius=R,
                 normal=HalfSineNormal(M * VN * (1 + E), TC), area=HalfSineArea(150e-6, TC),
                 compliance=Compliance(k, c) if compliant else None, effects=frozenset(effects))


@pytest.fixture(scope="module")
def bounce():
    return simulate("coulomb", golf(), {"mu": MU}, solver="ode", n=901)


def test_spin_reverses_before_end_of_contact(bounce):
    tr = bounce
    w = tr.v - R * tr.omega  # tangential velocity of the contact point
    i = int(np.argmax(tr.omega))
    assert 0 < tr.t[i] < 0.8 * TC  # spin peaks inside the contact ...
    assert tr.omega[-1] < 0.8 * tr.omega[i]  # ... and falls clearly before rebound
    assert np.any(tr.force < 0) and tr.force[0] >= 0  # friction reverses
    assert w[0] > 0 and w.min() < -0.25 * VT  # the contact point reverses (MBF)
    t_rev = tr.t[np.argmax(w < 0)]
    assert t_rev < TC


def test_rigid_model_cannot_reverse():
    rigid = simulate("coulomb", golf(compliant=False), {"mu": MU}, solver="exact", n=901)
    assert np.all(np.diff(rigid.omega) >= 0)
    assert np.all(rigid.v - R * rigid.omega >= 0)
    assert rigid.omega[-1] == pytest.approx(5 * VT / (7 * R), rel=1e-12)


def test_friction_stays_inside_the_coulomb_cone(bounce):
    """|F| <= mu N always; |F| = mu N wherever the patch slips."""
    tr = bounce
    N = tr.N
    assert np.all(np.abs(tr.force) <= MU * N * (1 + 1e-9) + 1e-9)
    slipping = (np.abs(tr.u) > 1e-9) & (N > 0)
    assert slipping.any() and (~slipping).any()
    assert np.allclose(np.abs(tr.force[slipping]), MU * N[slipping], rtol=1e-9)
    assert np.all(np.sign(tr.force[slipping]) == np.sign(tr.u[slipping]))


def test_energy_never_increases(bounce):
    """Body kinetic energy plus spring energy can only be lost (to friction and the damper)."""
    tr = bounce
    plan = make_plan(golf(), get_law("coulomb"))
    # rebuild xi from the force: F = k xi + c (w - u)  =>  xi = (F - c (w - u)) / k
    w = tr.v - R * tr.omega
    xi = (tr.force - C * (w - tr.u)) / K
    energy = 0.5 * M * tr.v**2 + 0.5 * plan.scene.inertia * tr.omega**2 + 0.5 * K * xi**2
    assert np.all(np.diff(energy) <= 1e-9 * energy[0])
    assert energy[-1] < energy[0]


def test_methods_agree(bounce):
    for method in ("RK45", "Radau", "DOP853"):
        other = simulate("coulomb", golf(), {"mu": MU}, solver=f"ode:{method}", n=901)
        for name in ("v", "omega", "theta", "force"):
            a, b = getattr(other, name), getattr(bounce, name)
            assert np.max(np.abs(a - b)) <= 1e-6 * np.max(np.abs(b)), (method, name)


def test_linear_law_matches_an_independent_integration():
    """For F = lam A u the compliant contact is linear: u = (k xi + c w) / (lam A + c). Integrate that here."""
    lam = 1e6
    s = golf()
    tr = simulate("wear", s, {"lam": lam}, solver="ode", n=201, rtol=1e-11)
    inertia = 0.4 * M * R**2

    def rhs(t, y):
        v, om, xi = y
        A = 150e-6 * math.sin(math.pi * t / TC)
        w = v - R * om
        u = (K * xi + C * w) / (lam * A + C)
        F = lam * A * u
        return [-F / M, F * R / inertia, w - u]

    ref = solve_ivp(rhs, (0, TC), [VT, 0.0, 0.0], t_eval=tr.t, rtol=1e-12, atol=1e-14, method="DOP853")
    assert np.max(np.abs(tr.v - ref.y[0])) < 1e-8 * VT
    assert np.max(np.abs(tr.omega - ref.y[1])) < 1e-8 * VT / R


def test_very_stiff_compliance_recovers_the_rigid_bounce():
    """k -> infinity (critically damped): the spring barely deflects; v at rebound -> 5 u0 / 7."""
    k = 1e10
    c = 2 * math.sqrt(k * MEFF)
    tr = simulate("coulomb", golf(k=k, c=c), {"mu": MU}, solver="ode", n=201)
    assert tr.v[-1] == pytest.approx(5 * VT / 7, rel=2e-3)
    assert tr.omega[-1] == pytest.approx(5 * VT / (7 * R), rel=2e-3)


def test_no_force_after_contact():
    tr = simulate("coulomb", golf(duration=1.5 * TC), {"mu": MU}, solver="ode", n=301)
    after = tr.t > TC * 1.001
    assert np.all(tr.force[after] == 0)
    assert np.ptp(tr.omega[after]) == 0 and np.ptp(tr.v[after]) == 0


def test_compliance_is_ode_only_and_needs_damping():
    with pytest.raises(SolverError, match="compliance"):
        simulate("coulomb", golf(), {"mu": MU}, solver="exact")
    with pytest.raises(SolverError, match="compliance"):
        simulate("wear", golf(), {"lam": 1e6}, solver="series")
    with pytest.raises(SceneError, match="Compliance.damping"):
        Compliance(1e6, 0.0)
    with pytest.raises(SceneError, match="compliance"):
        make_plan(golf().with_(compliance=None), get_law("coulomb"))
