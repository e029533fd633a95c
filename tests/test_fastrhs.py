"""The scalar right-hand side on floats (solve.fastrhs) against the general one (Plan._one_state), and whole
ODE fits and solves with it against the general path."""
import math

import numpy as np
import pytest

from frictionlab import fit, load_dataset, simulate
from frictionlab.physics.registry import get_law
from frictionlab.physics.scene import ConstantArea, G, GrowthArea, HalfSineArea, HalfSineNormal, Scene, WeightNormal
from frictionlab.solve import fastrhs
from frictionlab.solve.plan import make_plan

M, R = 0.046, 0.0213


def scenes():
    a = 0.3
    w = WeightNormal(0.02 * G * math.cos(a))
    yield Scene(kind="incline", mass=0.02, u0=0.1, duration=1.0, incline=a, area=GrowthArea(1e-5, 2e-5), normal=w,
                effects=frozenset({"gravity"}))
    yield Scene(kind="incline", mass=0.02, u0=0.1, duration=1.0, incline=a, area=ConstantArea(4e-4), normal=w,
                effects=frozenset({"gravity"}))
    yield Scene(kind="incline", mass=0.02, u0=0.1, duration=0.2, incline=a, area=HalfSineArea(1e-4, 0.07), normal=w,
                effects=frozenset({"gravity"}))
    yield Scene(kind="impact", mass=M, u0=20.0, duration=500e-6, radius=R, normal=HalfSineNormal(2.0, 450e-6),
                area=HalfSineArea(150e-6, 450e-6), effects=frozenset({"slip-coupling", "spin"}))
    yield Scene(kind="impact", mass=M, u0=12.0, duration=500e-6, radius=R, area=HalfSineArea(130e-6, 500e-6),
                effects=frozenset({"spin"}))


PARAMS = {"coulomb": {"mu": 0.3}, "area-rate": {"mu": 0.3, "eta_prime": 150.0}, "wear": {"lam": 1.5e6},
          "couette": {"eta": 0.1, "h": 1e-5}}


@pytest.mark.parametrize("law", sorted(PARAMS))
def test_float_rhs_equals_the_general_one(law):
    rng = np.random.default_rng(4)
    checked = 0
    for scene in scenes():
        lw = get_law(law)
        if set(lw.requires) - scene.supplies():
            continue
        plan = make_plan(scene, lw)
        p = lw.resolve(PARAMS[law])
        for direction in (0.0, 1.0, -1.0):
            from frictionlab.solve.solvers.stick import vanishing_slip

            fast = fastrhs.scalar_rhs(plan, p, direction, float(vanishing_slip(plan)))
            assert fast is not None, (law, scene.kind)
            for _ in range(20):
                t = rng.uniform(-0.1, 1.2) * scene.duration
                y = plan.initial_state(p) * rng.uniform(-1.5, 1.5, len(plan.states)) + rng.normal(0, 1e-3, len(plan.states))
                want = plan._one_state(p, t, y, direction, plan._fixed_normal())
                got = fast(t, y)
                assert got.shape == want.shape
                np.testing.assert_allclose(got, want, rtol=1e-13, atol=1e-13 * np.max(np.abs(want)))
                checked += 1
    assert checked >= 60


def test_unknown_models_and_plugins_take_the_general_path():
    from frictionlab.physics.scene import HertzNormal

    scene = Scene(kind="impact", mass=M, u0=20.0, duration=500e-6, radius=R, normal=HertzNormal(1e9), area=HalfSineArea(150e-6, 450e-6),
                  effects=frozenset({"slip-coupling", "spin"}))
    law = get_law("coulomb")
    assert fastrhs.scalar_rhs(make_plan(scene, law), law.resolve({"mu": 0.3}), 1.0) is None
    lugre = get_law("lugre")
    assert fastrhs.scalar_rhs(make_plan(scene, lugre), lugre.resolve({}), 1.0) is None


@pytest.mark.parametrize("law", ["area-rate", "wear", "couette", "coulomb"])
def test_ode_fits_with_and_without_it_agree(law, monkeypatch):
    ds = load_dataset("incline-dry-d10")
    fast = fit(law, ds, solver="ode")
    monkeypatch.setattr(fastrhs, "scalar_rhs", lambda *a: None)
    slow = fit(law, ds, solver="ode")
    assert fast.status == slow.status
    for name, pr in slow.params.items():
        if pr.stderr:
            assert abs(fast.params[name].value - pr.value) <= 1e-4 * pr.stderr
        else:
            assert fast.params[name].value == pytest.approx(pr.value, rel=1e-9)


def test_ode_solve_with_and_without_it_agree(monkeypatch):
    scene = list(scenes())[3]
    fast = simulate("area-rate", scene, PARAMS["area-rate"], solver="ode")
    monkeypatch.setattr(fastrhs, "scalar_rhs", lambda *a: None)
    slow = simulate("area-rate", scene, PARAMS["area-rate"], solver="ode")
    np.testing.assert_allclose(fast.omega, slow.omega, rtol=1e-9, atol=1e-9 * np.max(np.abs(slow.omega)))
    assert (fast.stick_time is None) == (slow.stick_time is None)


@pytest.mark.parametrize("law", ["wear", "couette"])
def test_the_scaled_float_rhs_of_a_slip_that_keeps_its_sign_equals_the_general_one(law):
    """``scaled_slip_rhs`` (the ODE solver's right-hand side where the slip keeps its sign) against the scaled
    general right-hand side, on the incline scenes driven down their slope."""
    from frictionlab.solve.solvers import ode
    from frictionlab.solve.solvers.stick import vanishing_slip

    rng = np.random.default_rng(7)
    lw = get_law(law)
    p = lw.resolve(PARAMS[law])
    checked = 0
    for scene in scenes():
        plan = make_plan(scene, lw)
        if not ode.slip_keeps_sign(plan, p, 1.0):
            continue
        T, scale = scene.duration, rng.uniform(0.5, 2.0, len(plan.states))
        general = ode._scaled_rates(plan, p, 1.0, T, scale, "LSODA")
        lean = fastrhs.scaled_slip_rhs(plan, p, 1.0, float(vanishing_slip(plan)), T, scale, general)
        assert lean is not None, plan.states
        for _ in range(30):
            s, z = rng.uniform(0.0, 1.0), rng.uniform(-0.2, 2.0, len(plan.states))
            np.testing.assert_allclose(lean(s, z), general(s, z), rtol=1e-13, atol=1e-13 * np.max(np.abs(general(s, z))))
            checked += 1
    assert checked >= 90
