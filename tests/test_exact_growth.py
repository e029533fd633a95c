"""The area-rate law's closed form on a growth area (an incline whose contact wears, A = A0 + rate x).

F = s (a N + c dA/dt) with dA/dt = rate |u| is F = s a N + c rate u: slip relaxes linearly, and the exact
solver's closed form (``solvers.exact``) must match a tight ODE solve of the same scene, through stops,
stuck phases and breakaways, and the batch engine must match the scalar solver.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from frictionlab import Scene, simulate
from frictionlab.core.errors import SolverError
from frictionlab.solve.choice import applicable_solvers, auto_solver
from frictionlab.io.dataset import load_dataset
from frictionlab.physics.scene import G, GrowthArea, HalfSineArea, HalfSineNormal, WeightNormal
from frictionlab.solve.batch import simulate_batch
from frictionlab.solve.solvers import area_slip


def worn_incline(alpha_deg=30.0, u0=0.0, mass=1.15e-3, duration=1.0, A0=1e-7, rate=1e-6, rolling=False):
    """A body on an incline whose contact grows as it slides (a sphere rolling with slip coupling if asked)."""
    a = math.radians(alpha_deg)
    effects = {"gravity"} | ({"slip-coupling"} if rolling else set())
    return Scene(kind="incline", mass=mass, u0=u0, duration=duration, incline=a, area=GrowthArea(A0, rate),
                 normal=WeightNormal(mass * G * math.cos(a)), effects=frozenset(effects),
                 radius=5e-3 if rolling else None)


# (scene, parameters, segments the exact solve takes): each a different branch of the closed form
CASES = {
    # the built-in incline-dry set's fitted region: from rest, sliding throughout (lam = 10/s)
    "steep from rest": (lambda: worn_incline(), {"mu": 4e-4, "eta_prime": 2.9e7}, 1),
    "sliding down": (lambda: worn_incline(u0=1.0), {"mu": 0.2, "eta_prime": 1e8}, 1),
    "shallow stops and sticks": (lambda: worn_incline(10.0, u0=1.0), {"mu": 0.5, "eta_prime": 1e8}, 2),
    "thrown up, stops, slides down": (lambda: worn_incline(u0=-1.0), {"mu": 0.1, "eta_prime": 1e7}, 3),
    "thrown up a shallow slope, sticks": (lambda: worn_incline(10.0, u0=-0.5), {"mu": 0.3, "eta_prime": 3e6}, 2),
    "eta' < 0: slip grows": (lambda: worn_incline(u0=0.3), {"mu": 0.2, "eta_prime": -3e4}, 1),
    "eta' < 0, stops before it runs away": (lambda: worn_incline(10.0, u0=0.2), {"mu": 0.6, "eta_prime": -1e4}, 2),
    "large rate (lam dt = 4.3e3)": (lambda: worn_incline(u0=2.0, rate=1e-6), {"mu": 0.05, "eta_prime": 1e8}, 1),
    "small rate (lam dt = 1e-9)": (lambda: worn_incline(u0=0.5), {"mu": 0.2, "eta_prime": 5.75e-6}, 1),
    "small rate (lam dt = 1e-4)": (lambda: worn_incline(u0=0.5), {"mu": 0.2, "eta_prime": 0.575}, 1),
    "rolling sphere": (lambda: worn_incline(u0=0.8, rolling=True), {"mu": 0.05, "eta_prime": 3e7}, 1),
    "rolling sphere sticks": (lambda: worn_incline(20.0, u0=0.4, rolling=True), {"mu": 0.6, "eta_prime": 3e7}, 2),
    "micro scale": (lambda: worn_incline(u0=1e-6, mass=1e-12, duration=1e-3, A0=1e-14, rate=1e-12),
                    {"mu": 0.3, "eta_prime": 1e4}, 1),
    "heavy and slow": (lambda: worn_incline(25.0, u0=1e3, mass=1e4, duration=1e4, A0=1.0, rate=1e-3),
                       {"mu": 0.6, "eta_prime": 5e4}, 2),
}

STATES = ("u", "v", "omega", "theta", "force", "A")


def _rel(x, y) -> float:
    return float(np.max(np.abs(np.asarray(x) - np.asarray(y))) / max(np.max(np.abs(y)), 1e-300))


@pytest.mark.parametrize("case", list(CASES))
def test_closed_form_matches_a_tight_ode_solve(case):
    scene, p, segments = CASES[case]
    s = scene()
    ex = simulate("area-rate", s, p, solver="exact", n=401)
    od = simulate("area-rate", s, p, solver="ode:DOP853", rtol=1e-12, n=401)
    assert ex.solver == "exact" and ex.info["segments"] == segments
    assert od.info["segments"] == segments
    if ex.stick_time is None:
        assert od.stick_time is None
    else:
        assert od.stick_time == pytest.approx(ex.stick_time, rel=1e-9)
        assert np.array_equal(ex.u == 0, od.u == 0)  # the same samples stuck
        near = np.abs(ex.t - ex.stick_time) < 1e-8 * ex.t[-1]  # the force jumps at a stick
        od.force[near] = ex.force[near]
    for name in STATES:
        if np.any(getattr(od, name)):
            assert _rel(getattr(ex, name), getattr(od, name)) <= 1e-9, name
    assert ex.A[-1] > s.area.initial or not np.any(ex.u)  # the area grew with the sliding length


def test_breakaway_after_a_stop_slides_the_other_way():
    tr = simulate("area-rate", CASES["thrown up, stops, slides down"][0](), {"mu": 0.1, "eta_prime": 1e7},
                  solver="exact", n=401)
    assert tr.u[0] < 0 and tr.u[-1] > 0
    assert np.all(np.diff(tr.A) >= 0)  # the contact wears on both ways


@pytest.mark.parametrize("lam", [-50.0, -1e-12, 0.0, 1e-12, 3.0, 1e4])
def test_stop_time_is_the_zero_of_the_closed_form(lam):
    """``relax_stop`` against a root of the relaxing slip itself, on both sides of lam = 0."""
    from scipy.optimize import brentq

    b, t0, T = -2.0, 0.25, 10.0
    g0 = 0.02 if lam < -1 else 0.7  # with lam < 0 below the unstable rest b / lam = 0.04

    def g(t):
        return float(area_slip._relax(g0, b, lam, t - t0)[0])

    assert g(t0) == g0 and g(T) < 0
    ts = float(area_slip.relax_stop(g0, b, lam, t0, T, 0.0))
    assert ts == pytest.approx(brentq(g, t0, T, xtol=1e-15), rel=1e-12)
    assert float(area_slip.relax_stop(g0, -b, lam, t0, T, 0.0)) == math.inf  # slip pushed on: no stop
    assert float(area_slip.relax_stop(g0, b, lam, t0, 0.9 * ts, 0.0)) == math.inf  # not by T
    if lam < -1:  # above the unstable rest slip runs away
        assert float(area_slip.relax_stop(0.05, b, lam, t0, 1e9, 0.0)) == math.inf


def test_batch_matches_the_scalar_solver():
    rng = np.random.default_rng(7)
    scenes, params = [], []
    for _ in range(24):
        scenes.append(worn_incline(rng.uniform(5, 40), u0=rng.choice([-1.0, 0.0, 1.0]) * rng.uniform(0.1, 2),
                                   rate=10 ** rng.uniform(-8, -5)))
        params.append({"mu": rng.uniform(0.05, 0.8), "eta_prime": rng.uniform(-1e6, 1e8)})
    br = simulate_batch("area-rate", scenes, params, solver="exact", n=301)
    assert br.solver == "exact"
    segs = set()
    for i, (s, p) in enumerate(zip(scenes, params)):
        tr = simulate("area-rate", s, p, solver="exact", n=301)
        segs.add(tr.info["segments"])
        for name in STATES:
            assert _rel(getattr(br, name)[i], getattr(tr, name)) <= 1e-12 or not np.any(getattr(tr, name)), (i, name)
        assert (math.isnan(br.stick_time[i]) if tr.stick_time is None
                else br.stick_time[i] == pytest.approx(tr.stick_time, rel=1e-12))
        assert br.info["segments_per_scene"][i] == tr.info["segments"]
    assert {1, 2, 3} <= segs  # slides throughout (or held from rest), sticks for good, breaks away after a stop


def test_batch_of_constant_areas_each_its_own():
    """A batch whose scenes differ in their constant area (a column of areas) against the scalar solver."""
    from frictionlab.physics.scene import ConstantArea

    rng = np.random.default_rng(3)
    scenes = [worn_incline(rng.uniform(10, 40), u0=rng.uniform(-1, 1)).with_(area=ConstantArea(rng.uniform(1e-5, 1e-4)))
              for _ in range(8)]
    params = [{"mu": rng.uniform(0.1, 0.6), "eta_prime": rng.uniform(-1e3, 1e6)} for _ in range(8)]
    br = simulate_batch("area-rate", scenes, params, solver="exact", n=201)
    for i, (s, p) in enumerate(zip(scenes, params)):
        tr = simulate("area-rate", s, p, solver="exact", n=201)
        for name in ("u", "v", "force"):
            assert _rel(getattr(br, name)[i], getattr(tr, name)) <= 1e-12, (i, name)


def test_the_comparison_fits_the_worn_inclines_in_closed_form():
    for name in ("incline-dry-d10", "incline-dry-d12p7"):
        scene = load_dataset(name).scene
        assert isinstance(scene.area, GrowthArea)
        assert applicable_solvers("area-rate", scene)["exact"] is None
        assert auto_solver("area-rate", scene) == "exact"
        # F = k A u on a growth area has no closed form here: still the ODE
        assert auto_solver("wear", scene) == "ode"


def test_unsupported_growth_scenes_say_why():
    impact = Scene(kind="impact", mass=0.046, u0=12.0, duration=500e-6, radius=0.0213,
                   area=GrowthArea(1e-6, 1e-4), normal=HalfSineNormal(1.77, 500e-6),
                   effects=frozenset({"spin", "slip-coupling"}))
    with pytest.raises(SolverError, match="growth area needs a weight normal force"):
        simulate("area-rate", impact, {"mu": 0.3, "eta_prime": 1e3}, solver="exact")
    with pytest.raises(SolverError, match="closed form only with a half-sine area"):
        simulate("wear", worn_incline(u0=1.0), {"lam": 1e5}, solver="exact")
    ok = simulate("area-rate", impact.with_(area=HalfSineArea(1e-4, 500e-6)), {"mu": 0.3, "eta_prime": 1e3},
                  solver="exact")
    assert ok.solver == "exact"


@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")  # the ODE solver's steps on the way
def test_a_runaway_slip_is_a_clear_error_not_a_nan():
    """eta' far below zero makes the friction push the slip on, exp(|lam| t) past the largest float: the exact
    solver says so, as the ODE solver does."""
    from frictionlab.core.errors import FrictionLabError

    for solver in ("exact", "ode"):
        with pytest.raises(FrictionLabError, match="NaN or infinite"):
            simulate("area-rate", worn_incline(u0=0.3), {"mu": 0.2, "eta_prime": -1e9}, solver=solver)
