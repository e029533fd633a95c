"""Hard cases: each states its expectation, a tolerance against an exact reference or a clear error.

References are closed forms written out here: eq (6) of the paper for F = k A u on a
half-sine area; for a rigid sphere with slip coupling under Coulomb friction and a
half-sine normal force N = Np sin(phi t), slip stops when mu Np (1 - cos(phi t)) / phi
reaches (2/7) m u0, after which the ball rolls with v = 5 u0 / 7.
"""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from _scenes import MASS, RADIUS, incline, normal_impact, paper_impact

from frictionlab import FrictionLaw, ParamSpec, simulate
from frictionlab.core.errors import LawError, ParameterError, SceneError, SolverError
from frictionlab.physics.scene import HalfSineArea, TableArea
from frictionlab.solve.solvers.series import SeriesAccuracyWarning

TC, A0 = 500e-6, 130e-6
KAPPA_COUPLED = 7 / (2 * MASS)  # 1/m + r^2/I for a solid sphere


def lam_for(b, tc=TC, area=A0, coupled=False):
    """lambda giving the dimensionless b = kappa lam A0 / phi (b = lam A0 / (m phi) without coupling)."""
    kappa = KAPPA_COUPLED if coupled else 1 / MASS
    return b * (math.pi / tc) / (kappa * area)


def rel_err(a, b):
    return np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300)


def assert_finite(tr):
    for name, arr in tr.columns().items():
        assert np.all(np.isfinite(arr)), name


def assert_matches(tr, ref, rel=1e-8, names=("u", "v", "omega", "theta")):
    for name in names:
        err = rel_err(getattr(tr, name), getattr(ref, name))
        assert err <= rel, f"{name}: relative error {err:.2e} > {rel:g}"


def eq6(u0, b, t, tc=TC):
    return u0 * np.exp(b * np.cos(math.pi * np.minimum(t, tc) / tc) - b)


def stick_time(u0, vn, e, mu, tc=TC):
    phi = math.pi / tc
    Np = MASS * vn * (1 + e) * phi / 2
    return math.acos(1 - (2 / 7) * MASS * u0 * phi / (mu * Np)) / phi


# --- b from 1e-6 to 1e3, lambda up to its bound --------------------------------------------------
@pytest.mark.parametrize("b", [1e-6, 1e-3, 0.1, 0.81, 10.0, 1e3])
@pytest.mark.parametrize("coupled", [False, True])
def test_b_range_exact_is_eq6_and_ode_agrees(b, coupled):
    scene = paper_impact(28, coupled=coupled)
    lam = lam_for(b, coupled=coupled)
    ex = simulate("wear", scene, {"lam": lam}, solver="exact", n=201)
    assert_finite(ex)
    # u comes from the states (v = u0 - J/m): absolute accuracy ~1e-15 u0 once u << u0
    assert np.allclose(ex.u, eq6(12.0, b, ex.t), rtol=1e-12, atol=1e-14 * 12.0)
    assert np.all(ex.u >= 0) and np.all(np.diff(ex.omega) >= 0)
    for method in ("LSODA", "DOP853"):
        od = simulate("wear", scene, {"lam": lam}, solver=f"ode:{method}", n=201)
        assert_finite(od)
        assert_matches(od, ex, 1e-8)


@pytest.mark.parametrize("b", [1e-6, 0.81, 1e3])
def test_b_range_series_stays_finite_and_warns_outside_its_range(b):
    scene = paper_impact(28)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        tr = simulate("wear", scene, {"lam": lam_for(b)}, solver="series")
    assert_finite(tr)
    warned = [w for w in caught if issubclass(w.category, SeriesAccuracyWarning)]
    assert bool(warned) == (b > 0.1)
    if warned:
        assert f"b = {b:.3g}" in str(warned[0].message)


@pytest.mark.parametrize("lam", [1e12, 1e13])
def test_huge_lambda_slip_dies_without_nan(lam):
    """b = 4.5e5 and 4.5e6: u0 exp(-2b) underflows to 0; spin is (r/I) m u0 = 5 u0 / (2r) at t_c."""
    scene = paper_impact(28)
    ex = simulate("wear", scene, {"lam": lam}, solver="exact", n=101)
    od = simulate("wear", scene, {"lam": lam}, solver="ode", n=101)
    for tr in (ex, od):
        assert_finite(tr)
        assert np.all(tr.u >= 0) and tr.u[-1] == pytest.approx(0, abs=1e-12)
        assert tr.omega[-1] == pytest.approx(5 * 12.0 / (2 * RADIUS), rel=1e-10)
    assert_matches(od, ex, 1e-8)


def test_lambda_above_its_bound_is_a_parameter_error():
    with pytest.raises(ParameterError, match=r"'wear': lam = .* outside its bounds"):
        simulate("wear", paper_impact(28), {"lam": 1e14})


# --- contact times 1 ns to 1 s, areas from 1e-12 m^2 -----------------------------------------------
@pytest.mark.parametrize("tc", [1e-9, 1e-6, 1e-3, 1.0])
def test_contact_time_range_wear(tc):
    """b = 0.81 at every contact time (lambda scaled with 1/t_c): the solution is the same in t / t_c."""
    scene = paper_impact(28, duration=tc, area=HalfSineArea(A0, tc))
    lam = lam_for(0.81, tc=tc)
    for solver in ("exact", "ode", "ode:RK45"):
        tr = simulate("wear", scene, {"lam": lam}, solver=solver, n=101)
        assert_finite(tr)
        assert rel_err(tr.u, eq6(12.0, 0.81, tr.t, tc)) < 1e-8
        assert tr.omega[-1] == pytest.approx(5 * 12.0 / (2 * RADIUS) * (1 - math.exp(-1.62)), rel=1e-8)


@pytest.mark.parametrize("tc", [1e-9, 1e-6, 1e-3, 1.0])
def test_contact_time_range_coulomb_stick(tc):
    scene = normal_impact(tc=tc)
    ts = stick_time(12.0, 24.0, 0.6, 0.3, tc)
    for solver in ("exact", "ode", "ode:DOP853"):
        tr = simulate("coulomb", scene, {"mu": 0.3}, solver=solver, n=101)
        assert_finite(tr)
        assert tr.stick_time == pytest.approx(ts, rel=1e-8)
        assert tr.v[-1] == pytest.approx(5 * 12.0 / 7, rel=1e-8)


@pytest.mark.parametrize("area", [1e-12, 1e-9, 1e-6, 1e-3, 1.0])
def test_contact_area_range(area):
    """lambda = b m phi / A0 for b = 0.81, capped at its bound 1e13 (b = 0.035 at A0 = 1e-12 m^2)."""
    lam = min(lam_for(0.81, area=area), 1e13)
    b = lam * area / (MASS * math.pi / TC)
    scene = paper_impact(28, area=HalfSineArea(area, TC))
    for solver in ("exact", "ode"):
        tr = simulate("wear", scene, {"lam": lam}, solver=solver, n=101)
        assert_finite(tr)
        assert rel_err(tr.u, eq6(12.0, b, tr.t)) < 1e-8
        assert tr.omega[-1] == pytest.approx(5 * 12.0 / (2 * RADIUS) * (1 - math.exp(-2 * b)), rel=1e-8)


def test_tiny_area_on_incline():
    """couette with A = 1e-12 m^2 on an incline: practically free sliding, u = u0 + g (sin alpha) t."""
    from frictionlab.physics.scene import G

    for solver in ("exact", "ode"):
        tr = simulate("couette", incline(u0=0.0, area=1e-12), {"eta": 1e-6, "h": 1.0}, solver=solver, n=51)
        assert_finite(tr)
        assert np.allclose(tr.u, G * math.sin(math.radians(20)) * tr.t, rtol=1e-9, atol=1e-15)


# --- slip starting at zero or reaching zero mid-contact --------------------------------------------
@pytest.mark.parametrize("solver", ["exact", "ode", "ode:RK45"])
def test_impact_starting_without_slip_stays_rolling(solver):
    """No slip, no drive: friction has nothing to oppose; the ball neither slips nor spins up."""
    tr = simulate("coulomb", normal_impact(u0=0.0), {"mu": 0.3}, solver=solver)
    assert np.all(tr.u == 0) and np.all(tr.omega == 0) and np.all(tr.force == 0)
    tr = simulate("wear", paper_impact(28, u0=0.0), {"lam": 1.81e6}, solver=solver)
    assert np.all(tr.u == 0) and np.all(tr.omega == 0)


@pytest.mark.parametrize("solver", ["exact", "ode", "ode:RK45", "ode:Radau"])
@pytest.mark.parametrize("mu, moves", [(0.2, True), (0.6, False), (math.tan(math.radians(20)), False)])
def test_incline_from_rest(solver, mu, moves):
    """From rest a block slides iff mu < tan(alpha); at mu = tan(alpha) exactly it stays (no chatter)."""
    from frictionlab.physics.scene import G

    a = math.radians(20)
    tr = simulate("coulomb", incline(u0=0.0), {"mu": mu}, solver=solver, n=101)
    assert tr.info["segments"] <= 2
    expected = G * (math.sin(a) - mu * math.cos(a)) * tr.t if moves else np.zeros_like(tr.t)
    assert np.allclose(tr.u, expected, rtol=1e-9, atol=1e-15)


def _sign_changes(u):
    s = np.sign(u[u != 0])
    return int(np.count_nonzero(np.diff(s)))


@pytest.mark.parametrize("solver", ["exact", "ode:LSODA", "ode:RK45", "ode:RK23", "ode:DOP853", "ode:Radau", "ode:BDF"])
@pytest.mark.parametrize("u0", [12.0, -12.0])
def test_coulomb_rolling_starts_at_the_exact_time_without_chatter(solver, u0):
    mu = 0.3
    tr = simulate("coulomb", normal_impact(u0=u0), {"mu": mu}, solver=solver, n=1001)
    ts = stick_time(abs(u0), 24.0, 0.6, mu)
    assert tr.stick_time == pytest.approx(ts, rel=1e-8)
    assert tr.info["segments"] == 2  # one slide, one stuck phase: no chatter
    assert _sign_changes(tr.u) == 0  # no sign flapping
    assert np.all(np.sign(tr.u[tr.t < ts]) == np.sign(u0))
    after = tr.t > ts
    assert np.all(tr.u[after] == 0) and np.all(tr.force[after] == 0)
    assert tr.v[-1] == pytest.approx(5 * u0 / 7, rel=1e-8)
    assert tr.omega[-1] == pytest.approx(5 * u0 / (7 * RADIUS), rel=1e-8)


@pytest.mark.parametrize("solver", ["exact", "ode", "ode:RK45", "ode:Radau"])
def test_slip_stopping_exactly_at_end_of_contact(solver):
    """mu chosen so the impulse mu m vn (1 + e) equals (2/7) m u0: slip reaches zero tangentially at t_c.

    The stick time of a cubic zero is ill-conditioned; the motion is not: no negative slip, final v = 5 u0 / 7.
    """
    mu = (2 / 7) * 12.0 / (24.0 * 1.6)
    tr = simulate("coulomb", normal_impact(), {"mu": mu}, solver=solver, n=201)
    assert_finite(tr)
    assert np.all(tr.u >= 0)
    assert tr.v[-1] == pytest.approx(5 * 12.0 / 7, rel=1e-8)
    assert tr.stick_time is None or tr.stick_time == pytest.approx(TC, rel=1e-4)


# --- measured area columns with noise ---------------------------------------------------------------
def _noisy_column(noise, step=10e-6, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, TC + step / 2, step)  # the paper's 10 us framing interval
    A = np.clip(A0 * np.sin(math.pi * t / TC) + noise * A0 * rng.standard_normal(t.size), 0, None)
    return t, A


@pytest.mark.parametrize("noise", [0.0, 0.01, 0.03])
def test_table_area_derivative_does_not_blow_up(noise):
    t, A = _noisy_column(noise)
    area = TableArea(t, A)
    tt = np.linspace(0, TC, 2001)
    a, dadt = area(tt)
    peak_rate = A0 * math.pi / TC
    assert np.max(np.abs(a - A0 * np.sin(math.pi * tt / TC))) < (0.002 + 1.5 * noise) * A0
    assert np.max(np.abs(dadt - peak_rate * np.cos(math.pi * tt / TC))) < (0.01 + 10 * noise) * peak_rate
    if noise >= 0.03:
        naive = np.diff(A) / np.diff(t)  # what plain differencing would give
        assert np.max(np.abs(naive)) > 1.5 * peak_rate


@pytest.mark.parametrize("solver", ["ode", "ode:RK45"])
def test_noisy_area_column_follows_the_half_sine_solution(solver):
    """3 % noise on the area: the spin stays within 2 % of the exact half-sine solution (wear),
    and within 3 % for the area-rate law, which reads dA/dt."""
    t, A = _noisy_column(0.03)
    wear = simulate("wear", paper_impact(28).with_(area=TableArea(t, A)), {"lam": 1.81e6}, solver=solver)
    ref = simulate("wear", paper_impact(28), {"lam": 1.81e6}, solver="exact")
    assert_finite(wear)
    assert rel_err(wear.omega, ref.omega) < 0.02
    p = {"mu": 0.3, "eta_prime": 1e3}
    ar = simulate("area-rate", normal_impact().with_(area=TableArea(t, A)), p, solver=solver)
    ref = simulate("area-rate", normal_impact(), p, solver="exact")
    assert_finite(ar)
    assert rel_err(ar.omega, ref.omega) < 0.03


@pytest.mark.parametrize("t, A, match", [
    (np.linspace(0, 1e-3, 4), np.ones(4), "at least 5"),
    (np.linspace(0, 1e-3, 6), -np.ones(6), "negative"),
    (np.linspace(0, 1e-3, 6), np.array([0, 1, np.nan, 1, 1, 0.0]), "finite"),
    (np.array([0, 1, 1, 2, 3, 4.0]), np.ones(6), "increase"),
])
def test_bad_area_columns_are_clear_errors(t, A, match):
    with pytest.raises(SceneError, match=match):
        TableArea(t, A)


# --- parameters at their bounds ---------------------------------------------------------------------
BOUNDS = {
    "coulomb mu=0": ("coulomb", normal_impact, {"mu": 0.0}),
    "coulomb mu=5": ("coulomb", normal_impact, {"mu": 5.0}),
    "wear lam=0": ("wear", lambda: paper_impact(28), {"lam": 0.0}),
    "wear lam=1e13 coupled": ("wear", lambda: paper_impact(28, coupled=True), {"lam": 1e13}),
    "area-rate eta'=+1e12": ("area-rate", normal_impact, {"mu": 0.3, "eta_prime": 1e12}),
    "area-rate eta'=-1e12": ("area-rate", normal_impact, {"mu": 0.3, "eta_prime": -1e12}),
    "area-rate mu=5": ("area-rate", normal_impact, {"mu": 5.0, "eta_prime": 0.0}),
    "couette eta/h=1e18": ("couette", lambda: incline(area=1e-3), {"eta": 1e6, "h": 1e-12}),
    "couette eta/h=1e-6": ("couette", lambda: incline(area=1e-3), {"eta": 1e-6, "h": 1.0}),
    "couette impact eta/h=1e18": ("couette", lambda: paper_impact(28), {"eta": 1e6, "h": 1e-12}),
}


@pytest.mark.parametrize("case", list(BOUNDS))
def test_parameters_at_bounds_match_exact(case):
    law, scene, p = BOUNDS[case]
    s = scene()
    ex = simulate(law, s, p, solver="exact", n=201)
    assert_finite(ex)
    for solver in ("ode", "ode:Radau"):
        od = simulate(law, s, p, solver=solver, n=201)
        assert_finite(od)
        if ex.stick_time is not None:
            assert od.stick_time == pytest.approx(ex.stick_time, rel=1e-8)
        assert_matches(od, ex, 1e-8)


def test_frictionless_bounds_leave_motion_unchanged():
    tr = simulate("coulomb", normal_impact(), {"mu": 0.0}, solver="ode")
    assert np.all(tr.u == 12.0) and np.all(tr.omega == 0)
    tr = simulate("wear", paper_impact(28), {"lam": 0.0}, solver="exact")
    assert np.all(tr.u == 12.0) and np.all(tr.omega == 0)


@pytest.mark.parametrize("law, p, match", [
    ("coulomb", {"mu": -0.1}, "mu = -0.1"),
    ("coulomb", {"mu": 5.1}, "mu = 5.1"),
    ("coulomb", {"mu": float("nan")}, "mu = nan"),
    ("couette", {"h": 0.0}, "h = 0.0"),
    ("coulomb", {"nu": 0.1}, "no parameter 'nu'"),
])
def test_out_of_bounds_parameters_are_errors(law, p, match):
    with pytest.raises(ParameterError, match=match):
        simulate(law, normal_impact(), p)


# --- no silent NaN ----------------------------------------------------------------------------------
class NaNLaw(FrictionLaw):
    name = "nan-law"
    formula = "F = k u, NaN once u < 1 m/s"
    citation = "test"
    params = (ParamSpec("k", "N s/m", 1.0, 0.0, 10.0, 1.0, "coefficient"),)
    requires = frozenset({"u"})

    def force(self, p, c):
        return np.where(np.abs(c.u) < 1.0, np.nan, p["k"] * c.u)


@pytest.mark.parametrize("solver", ["ode", "ode:RK45", "ode:Radau"])
def test_law_returning_nan_is_a_law_error(solver):
    with pytest.raises(LawError, match="'nan-law'.*NaN"):
        simulate(NaNLaw(), incline(u0=1.5, alpha_deg=1.0), {"k": 10.0}, solver=solver)


@pytest.mark.parametrize("changes, match", [
    ({"mass": float("nan")}, "Scene.mass"),
    ({"mass": -1.0}, "Scene.mass"),
    ({"u0": float("inf")}, "Scene.u0"),
    ({"radius": 0.0}, "Scene.radius"),
    ({"area": "x"}, None),
])
def test_nan_or_nonsense_in_a_python_scene_is_an_error(changes, match):
    if match is None:
        with pytest.raises(Exception):
            simulate("wear", paper_impact(28).with_(**changes), {"lam": 1e6})
        return
    with pytest.raises(SceneError, match=match):
        paper_impact(28).with_(**changes)


def test_nan_model_numbers_are_errors():
    with pytest.raises(SceneError, match="HalfSineArea.contact_time"):
        HalfSineArea(1e-4, float("nan"))
    with pytest.raises(SceneError, match="HalfSineArea.peak"):
        HalfSineArea(-1e-4, 1e-3)


def test_bad_sample_times_are_errors():
    for t in ([0.0, float("nan")], [1e-4, 0.0], []):
        with pytest.raises(SolverError, match="t must be"):
            simulate("wear", paper_impact(28), {"lam": 1e6}, t=np.array(t))
