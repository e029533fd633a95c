"""Solvers through the public API: the paper's numbers, closed forms, and exact vs ode.

Expected values are computed here from the paper's formulas (Arakawa, Sci. Rep. 2017):
eq (1) A = A0 sin(phi t), phi = pi / t_c; eq (6) u = u0 exp(b cos(phi t) - b), b = lam A0 / (m phi);
eqs (9)-(11) omega = (5 u0 / 2r) b (1 - b)(1 - cos phi t) + (5 u0 / 4r) b^2 sin^2(phi t).
"""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from _scenes import MASS, PAPER, RADIUS, incline, normal_impact, paper_impact

from frictionlab import simulate
from frictionlab.core.errors import SolverError
from frictionlab.physics.scene import G, GrowthArea
from frictionlab.solve.solvers.series import SeriesAccuracyWarning

RPM = 30.0 / math.pi  # rad/s -> rpm


def series(law, scene, params, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SeriesAccuracyWarning)
        return simulate(law, scene, params, solver="series", **kw)


def b_of(c):
    return c["lam"] * c["A0"] / (MASS * math.pi / c["tc"])


# --- the paper's series, eqs (7)-(11) ------------------------------------------------------
@pytest.mark.parametrize("vi", [28, 61])
def test_series_reproduces_paper(vi):
    c = PAPER[vi]
    u0, tc, b = c["u0"], c["tc"], b_of(c)
    phi = math.pi / tc
    tr = series("wear", paper_impact(vi), {"lam": c["lam"]}, n=20001)
    # b as the paper states it (0.81 and 0.83)
    assert tr.info["b"] == pytest.approx(b, rel=1e-12)
    assert round(tr.info["b"], 2) == c["b"]
    # eq (9) has d omega/dt = 0 where cos(phi t) = -(1 - b)/b (for b > 1/2); there
    # omega = (5 u0 / 4r) [2 b (1 - b)(1 - cos) + b^2 sin^2] = 5 u0 / (4 r)
    t_peak = math.acos(-(1 - b) / b) / phi
    w_peak = 5 * u0 / (4 * RADIUS)
    i = int(np.argmax(tr.omega))
    assert tr.omega[i] == pytest.approx(w_peak, rel=1e-8)
    assert abs(tr.t[i] - t_peak) <= tr.t[1] - tr.t[0]
    # at t_c: omega_a = 0, omega_r = (5 u0 / r) b (1 - b)
    assert tr.omega[-1] == pytest.approx(5 * u0 / RADIUS * b * (1 - b), rel=1e-12)
    # largest rotation angle = theta(t_c) = t_c (5 u0 / 2r) [b (1 - b) + b^2 / 4] (eq 9 integrated)
    theta_c = tc * 5 * u0 / (2 * RADIUS) * (b * (1 - b) + b * b / 4)
    assert tr.theta[-1] == pytest.approx(theta_c, rel=1e-12)
    assert tr.theta.max() == tr.theta[-1]
    assert abs(math.degrees(theta_c) - c["theta_deg"]) < 0.5  # the paper's 13 and 26 deg
    # eq (7) slip and eq (3) force
    assert np.allclose(tr.u, u0 * (1 - b + b * np.cos(phi * tr.t)), rtol=1e-13, atol=1e-13 * u0)
    # the peak is where the truncated slip of eq (7) crosses zero: after it, eq (7) slides
    # backwards (u0 (1 - 2b) < 0 at t_c for b > 1/2) and the spin falls; the exact eq (6) never does
    assert u0 * (1 - b + b * math.cos(phi * t_peak)) == pytest.approx(0, abs=1e-12)
    assert tr.u[-1] == pytest.approx(u0 * (1 - 2 * b), rel=1e-12) and tr.u[-1] < 0
    assert np.allclose(tr.force, c["lam"] * c["A0"] * np.sin(phi * tr.t) * tr.u, rtol=1e-12, atol=1e-9)


def test_series_paper_numbers_in_rpm():
    """The values quoted in the task brief for V_i = 28 m/s, from eq (9)."""
    tr = series("wear", paper_impact(28), {"lam": 1.81e6}, n=5001)
    assert tr.omega.max() * RPM == pytest.approx(6725, abs=2)
    assert tr.omega[-1] * RPM == pytest.approx(4071, abs=2)
    assert 280e-6 < tr.t[np.argmax(tr.omega)] < 295e-6


def test_series_warns_naming_b():
    with pytest.warns(SeriesAccuracyWarning, match=r"b = 0\.814"):
        simulate("wear", paper_impact(28), {"lam": 1.81e6}, solver="series")
    with warnings.catch_warnings():
        warnings.simplefilter("error", SeriesAccuracyWarning)
        simulate("wear", paper_impact(28), {"lam": 1e4}, solver="series")  # b = 0.0045: quiet


def test_series_refuses_other_laws_and_scenes():
    with pytest.raises(SolverError, match="coulomb"):
        simulate("coulomb", normal_impact(coupled=False), {"mu": 0.3}, solver="series")
    with pytest.raises(SolverError, match="slip coupling"):
        series("wear", paper_impact(28, coupled=True), {"lam": 1.81e6})
    with pytest.raises(SolverError, match="impact scene"):
        series("couette", incline(area=1e-3), {"eta": 0.1, "h": 1e-5})


def test_series_converges_to_exact_for_small_b():
    """The truncation error of eq (7) is O(b^2)."""
    # at t_c: series (5 u0 / r)(b - b^2), exact (5 u0 / 2r)(1 - exp(-2b)) = (5 u0 / r)(b - b^2 + 2 b^3 / 3 - ...):
    # relative difference 2 b^2 / 3 to leading order
    for b in (1e-3, 1e-2):
        lam = b * MASS * math.pi / (130e-6 * 500e-6)
        ex = simulate("wear", paper_impact(28), {"lam": lam}, solver="exact")
        se = series("wear", paper_impact(28), {"lam": lam})
        assert (ex.omega[-1] - se.omega[-1]) / ex.omega[-1] == pytest.approx(2 * b * b / 3, rel=2 * b)


# --- exact closed forms against formulas written out here ------------------------------------
@pytest.mark.parametrize("vi", [28, 61])
def test_exact_wear_is_eq6(vi):
    c = PAPER[vi]
    u0, b, phi = c["u0"], b_of(c), math.pi / c["tc"]
    tr = simulate("wear", paper_impact(vi), {"lam": c["lam"]}, solver="exact", n=401)
    assert np.allclose(tr.u, u0 * np.exp(b * np.cos(phi * tr.t) - b), rtol=1e-13, atol=0)
    # eq (2): omega = (r / I) int F dt = (r / I) m (u0 - u), monotonic
    w = RADIUS / (0.4 * MASS * RADIUS**2) * MASS * (u0 - tr.u)
    assert np.allclose(tr.omega, w, rtol=1e-12, atol=1e-9)
    assert np.all(np.diff(tr.omega) >= 0)
    assert tr.omega[-1] == pytest.approx(5 * u0 / (2 * RADIUS) * (1 - math.exp(-2 * b)), rel=1e-13)


def test_exact_paper_spin_in_rpm():
    tr = simulate("wear", paper_impact(28), {"lam": 1.81e6}, solver="exact")
    assert tr.omega[-1] * RPM == pytest.approx(10810, abs=1)


def test_exact_couette_incline_is_exponential_approach():
    eta, h, A, m, alpha = 0.1, 1e-5, 1e-3, 0.1, math.radians(20)
    tr = simulate("couette", incline(u0=1.0, area=A), {"eta": eta, "h": h}, solver="exact", n=101)
    tau = m * h / (eta * A)
    u_inf = m * G * h * math.sin(alpha) / (eta * A)
    assert np.allclose(tr.u, u_inf + (1.0 - u_inf) * np.exp(-tr.t / tau), rtol=1e-13, atol=0)
    assert np.all(tr.omega == 0)


def test_exact_coulomb_incline_slides_and_sticks():
    alpha = math.radians(20)
    slide = simulate("coulomb", incline(u0=1.0), {"mu": 0.2}, solver="exact", n=101)
    accel = G * (math.sin(alpha) - 0.2 * math.cos(alpha))
    assert np.allclose(slide.u, 1.0 + accel * slide.t, rtol=1e-14, atol=1e-14)
    assert slide.stick_time is None
    stick = simulate("coulomb", incline(u0=1.0), {"mu": 0.6}, solver="exact", n=101)
    t_s = 1.0 / (G * (0.6 * math.cos(alpha) - math.sin(alpha)))
    assert stick.stick_time == pytest.approx(t_s, rel=1e-13)
    after = stick.t > t_s
    assert np.all(stick.u[after] == 0) and np.all(stick.v[after] == 0)
    # held by static friction m g sin(alpha), below mu N
    assert np.allclose(stick.force[after], 0.1 * G * math.sin(alpha), rtol=1e-14)


def test_exact_coulomb_impact_rolls_after_two_sevenths_impulse():
    """Rigid sphere, slip coupling: slip stops when mu int N dt = (2/7) m u0; then it rolls."""
    mu, u0, vn, e, tc = 0.3, 12.0, 24.0, 0.6, 500e-6
    tr = simulate("coulomb", normal_impact(u0=u0, vn=vn, e=e, tc=tc), {"mu": mu}, solver="exact", n=501)
    phi = math.pi / tc
    Np = MASS * vn * (1 + e) * phi / 2
    t_s = math.acos(1 - (2 / 7) * MASS * u0 * phi / (mu * Np)) / phi
    assert tr.stick_time == pytest.approx(t_s, rel=1e-12)
    assert tr.v[-1] == pytest.approx(5 * u0 / 7, rel=1e-13)
    assert tr.omega[-1] == pytest.approx(5 * u0 / (7 * RADIUS), rel=1e-13)
    rolled = tr.t > t_s
    assert np.all(tr.u[rolled] == 0) and np.all(tr.force[rolled] == 0)


# --- exact vs ode on every closed form ---------------------------------------------------------
CASES = {
    "wear impact": ("wear", lambda: paper_impact(28), {"lam": 1.81e6}),
    "wear impact 61": ("wear", lambda: paper_impact(61), {"lam": 0.96e6}),
    "wear impact coupled": ("wear", lambda: paper_impact(28, coupled=True), {"lam": 1.81e6}),
    "couette impact": ("couette", lambda: paper_impact(28), {"eta": 1.81, "h": 1e-6}),
    "couette impact coupled": ("couette", lambda: paper_impact(28, coupled=True), {"eta": 1.81, "h": 1e-6}),
    "wear impact past contact": ("wear", lambda: paper_impact(28, duration=800e-6), {"lam": 1.81e6}),
    "couette incline": ("couette", lambda: incline(u0=1.0, area=1e-3), {"eta": 0.1, "h": 1e-5}),
    "couette incline from rest": ("couette", lambda: incline(u0=0.0, area=1e-3), {"eta": 0.1, "h": 1e-5}),
    "coulomb incline sliding": ("coulomb", lambda: incline(u0=1.0), {"mu": 0.2}),
    "coulomb incline sticks": ("coulomb", lambda: incline(u0=1.0), {"mu": 0.6}),
    "coulomb incline from rest": ("coulomb", lambda: incline(u0=0.0), {"mu": 0.2}),
    "coulomb impact rolls": ("coulomb", lambda: normal_impact(), {"mu": 0.3}),
    "coulomb impact slides": ("coulomb", lambda: normal_impact(), {"mu": 0.05}),
    "coulomb impact uncoupled stops": ("coulomb", lambda: normal_impact(u0=3.0, coupled=False), {"mu": 0.3}),
    "coulomb impact rolls past contact": ("coulomb", lambda: normal_impact(duration=700e-6), {"mu": 0.3}),
    "area-rate impact": ("area-rate", lambda: normal_impact(), {"mu": 0.3, "eta_prime": 1e3}),
    "area-rate impact slides": ("area-rate", lambda: normal_impact(), {"mu": 0.05, "eta_prime": 1e4}),
}


def _assert_agree(a, b, rel):
    for name in ("u", "v", "omega", "theta", "force"):
        x, y = getattr(a, name), getattr(b, name)
        scale = max(np.max(np.abs(x)), 1e-300)
        err = np.max(np.abs(x - y)) / scale
        assert err <= rel, f"{name}: relative difference {err:.2e}"


@pytest.mark.parametrize("case", list(CASES))
@pytest.mark.parametrize("method", ["LSODA", "DOP853", "Radau"])
def test_exact_and_ode_agree(case, method):
    law, scene, p = CASES[case]
    s = scene()
    ex = simulate(law, s, p, solver="exact", n=257)
    od = simulate(law, s, p, solver=f"ode:{method}", n=257)
    assert ex.solver == "exact" and od.solver == f"ode:{method}"
    if ex.stick_time is None:
        assert od.stick_time is None
    else:
        assert od.stick_time == pytest.approx(ex.stick_time, rel=1e-8)
        # the same samples are stuck (slip exactly zero) in both
        assert np.array_equal(ex.u == 0, od.u == 0)
        assert np.any(ex.u == 0)
    # the force jumps at a stick: compare it only where both are in the same phase
    if ex.stick_time is not None:
        near = np.abs(ex.t - ex.stick_time) < 1e-8 * ex.t[-1]
        od.force[near] = ex.force[near]
    _assert_agree(od, ex, 1e-8)


def test_area_rate_sticks_and_breaks_away():
    """While the contact unloads, mu eta' dA/dt < 0 can no longer hold the rolling ball: it slips again."""
    tr = simulate("area-rate", normal_impact(), {"mu": 0.3, "eta_prime": 1e3}, solver="exact", n=1001)
    assert tr.stick_time is not None and tr.info["segments"] >= 3
    stuck = tr.u == 0
    assert stuck.any() and (~stuck[tr.t > tr.stick_time]).any()


def test_unknown_solver_is_an_error():
    with pytest.raises(SolverError, match="unknown solver"):
        simulate("wear", paper_impact(28), {"lam": 1e6}, solver="magic")
    with pytest.raises(SolverError, match="unknown ODE method"):
        simulate("wear", paper_impact(28), {"lam": 1e6}, solver="ode:Euler")
    with pytest.raises(SolverError, match="closed form only with a half-sine area"):
        simulate("wear", paper_impact(28).with_(area=GrowthArea(1e-6, 1e-4)), {"lam": 1e6}, solver="exact")


def test_a_slip_that_keeps_its_sign_is_integrated_without_the_zero_slip_event():
    """F = k A u on a block driven down its slope cannot bring the slip to zero: LSODA then runs its loop in
    ODEPACK without the event, to the same accuracy as solve_ivp's loop watching it; driven against the slip, or
    with another form of law, or with spin, the event stays, and a block sent up the slope still stops."""
    import math

    from frictionlab import simulate
    from frictionlab.physics.registry import get_law
    from frictionlab.physics.scene import G, GrowthArea, HalfSineArea, HalfSineNormal, Scene, WeightNormal
    from frictionlab.solve.plan import make_plan
    from frictionlab.solve.solvers import ode

    a = 0.3

    def block(u0):
        return Scene(kind="incline", mass=0.02, u0=u0, duration=1.0, incline=a, area=GrowthArea(1e-5, 2e-5),
                     normal=WeightNormal(0.02 * G * math.cos(a)), effects=frozenset({"gravity"}))

    wear, coulomb = get_law("wear"), get_law("coulomb")
    p = wear.resolve({"lam": 1.5e6})
    down = make_plan(block(0.1), wear)
    assert ode.slip_keeps_sign(down, p, 1.0)
    assert not ode.slip_keeps_sign(down, p, -1.0) and not ode.slip_keeps_sign(down, p, 0.0)
    assert not ode.slip_keeps_sign(make_plan(block(0.1), coulomb), coulomb.resolve({"mu": 0.3}), 1.0)
    golf = Scene(kind="impact", mass=0.046, u0=20.0, duration=500e-6, radius=0.0213, normal=HalfSineNormal(2.0, 450e-6),
                 area=HalfSineArea(150e-6, 450e-6), effects=frozenset({"slip-coupling", "spin"}))
    assert not ode.slip_keeps_sign(make_plan(golf, wear), p, 1.0)

    t = np.linspace(0.0, 1.0, 200)
    ref = simulate(wear, block(0.1), p, solver="ode:Radau", t=t, rtol=1e-12)
    fast = simulate(wear, block(0.1), p, solver="ode", t=t, rtol=1e-8)
    keep = ode.slip_keeps_sign
    try:
        ode.slip_keeps_sign = lambda *args: False
        watched = simulate(wear, block(0.1), p, solver="ode", t=t, rtol=1e-8)
    finally:
        ode.slip_keeps_sign = keep
    scale = float(np.max(np.abs(ref.v)))
    err_fast, err_watched = (float(np.max(np.abs(x.v - ref.v))) / scale for x in (fast, watched))
    assert fast.stick_time is None and err_fast < 1e-6 and err_fast < 10 * err_watched
    up = simulate(wear, block(-3.0), p, solver="ode", t=t, rtol=1e-8)  # sent up the slope: stops, then slides down
    assert up.stick_time is not None and 0.0 < up.stick_time < 1.0
