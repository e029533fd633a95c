"""The plan builds only what the scene and the law need, and says clearly what is missing."""
from __future__ import annotations

import math

import numpy as np
import pytest
from _scenes import MASS, RADIUS, incline, normal_impact, paper_impact

from frictionlab import Scene, get_law, make_plan, simulate
from frictionlab.core.errors import SceneError
from frictionlab.physics.scene import (
    G,
    GrowthArea,
    HalfSineArea,
    HalfSineNormal,
    HertzNormal,
    WeightNormal,
)

SOLVERS = ("exact", "ode", "ode:RK45")


class Forbidden:
    """A contact model that must never be evaluated."""

    contact_time = 500e-6

    def __init__(self):
        self.calls = 0

    def __call__(self, *args, **kwargs):
        self.calls += 1
        raise AssertionError("this model must not be called")


@pytest.mark.parametrize("solver", SOLVERS + ("series",))
def test_wear_never_calls_the_normal_force_model(solver):
    forbidden = Forbidden()
    scene = paper_impact(28).with_(normal=forbidden)
    with pytest.warns(UserWarning) if solver == "series" else _nothing():
        tr = simulate("wear", scene, {"lam": 1.81e6}, solver=solver)
    assert forbidden.calls == 0
    assert tr.N is None and tr.A is not None
    assert np.all(np.isfinite(tr.omega))


@pytest.mark.parametrize("solver", SOLVERS)
def test_coulomb_never_calls_the_area_model(solver):
    forbidden = Forbidden()
    scene = incline(u0=1.0).with_(area=forbidden)
    tr = simulate("coulomb", scene, {"mu": 0.6}, solver=solver)
    assert forbidden.calls == 0 and tr.A is None


def test_incline_block_has_no_spin_state():
    for law, p, scene in (("couette", {"eta": 0.1, "h": 1e-5}, incline(area=1e-3)),
                          ("coulomb", {"mu": 0.2}, incline())):
        plan = make_plan(scene, get_law(law))
        assert plan.states == ("v",)
        assert not plan.has_spin
        tr = simulate(law, scene, p)
        assert np.all(tr.omega == 0) and np.all(tr.theta == 0)


def test_paper_scene_states():
    plan = make_plan(paper_impact(28), get_law("wear"))
    assert plan.states == ("v", "omega", "theta")
    assert not plan.coupled and plan.drive == 0.0 and not plan.needs_normal
    assert plan.kappa == pytest.approx(1 / MASS)
    coupled = make_plan(paper_impact(28, coupled=True), get_law("wear"))
    assert coupled.coupled
    assert coupled.kappa == pytest.approx(1 / MASS + RADIUS**2 / (0.4 * MASS * RADIUS**2))  # 7 / (2 m)


def test_growth_area_adds_sliding_length_only_when_area_is_read():
    s = incline(u0=0.5).with_(area=GrowthArea(1e-4, 1e-3))
    assert make_plan(s, get_law("wear")).states == ("v", "x")
    assert make_plan(s, get_law("coulomb")).states == ("v",)
    # a Hertz normal force reads the area, so coulomb then integrates x too
    hertz = s.with_(normal=HertzNormal(1e9))
    assert make_plan(hertz, get_law("coulomb")).states == ("v", "x")


def test_growth_area_trajectory_uses_sliding_length():
    s = incline(u0=0.5, alpha_deg=10).with_(area=GrowthArea(1e-4, 1e-3))
    tr = simulate("wear", s, {"lam": 1e3}, solver="ode")
    x = np.concatenate([[0.0], np.cumsum(np.diff(tr.t) * (tr.u[1:] + tr.u[:-1]) / 2)])  # trapezoid
    assert np.allclose(tr.A, 1e-4 + 1e-3 * x, rtol=1e-4)
    assert tr.A[-1] > tr.A[0]


def test_coulomb_without_normal_force_is_a_clear_error():
    with pytest.raises(SceneError) as err:
        simulate("coulomb", paper_impact(28), {"mu": 0.3})
    msg = str(err.value)
    assert "'coulomb'" in msg and "N (normal force)" in msg and "[scene.normal]" in msg
    assert "\n" not in msg
    with pytest.raises(SceneError, match="'area-rate'.*dAdt"):
        simulate("area-rate", incline(), {"mu": 0.3})
    with pytest.raises(SceneError, match="'wear'.*A \\(contact area\\)"):
        simulate("wear", incline(), {"lam": 1e3})


def test_hertz_normal_without_area_is_a_clear_error():
    s = incline().with_(normal=HertzNormal(1e9))
    with pytest.raises(SceneError, match="'coulomb'.*Hertz.*no \\[scene.area\\]"):
        make_plan(s, get_law("coulomb"))


def test_hertz_normal_reads_the_area():
    k = 2e9
    s = normal_impact().with_(normal=HertzNormal(k))
    tr = simulate("coulomb", s, {"mu": 0.01}, solver="ode")
    assert np.allclose(tr.N, k * (130e-6 * np.sin(math.pi * tr.t / 500e-6).clip(0)) ** 1.5, rtol=1e-12, atol=1e-9)


def test_scene_from_toml_spec():
    spec = {"mass": "46 g", "radius": "21.3 mm", "u0": "12 m/s", "effects": ["spin"],
            "area": {"model": "half-sine", "peak": "130 mm^2", "contact_time": "500 us"}}
    s = Scene.from_spec(spec, "impact", "test.toml")
    assert s.mass == pytest.approx(0.046) and s.radius == pytest.approx(0.0213) and s.u0 == 12.0
    assert isinstance(s.area, HalfSineArea)
    assert (s.area.peak, s.area.contact_time) == (pytest.approx(130e-6), pytest.approx(500e-6))
    assert s.duration == pytest.approx(500e-6) and s.normal is None
    assert make_plan(s, get_law("wear")).states == ("v", "omega", "theta")

    inc = Scene.from_spec({"mass": "100 g", "u0": "0 m/s", "incline": "20 deg", "duration": "2 s",
                           "area": {"model": "constant", "area": "10 cm^2"}}, "incline", "inc.toml")
    assert "gravity" in inc.effects
    assert isinstance(inc.normal, WeightNormal)
    assert inc.normal.value == pytest.approx(0.1 * G * math.cos(math.radians(20)))

    imp = Scene.from_spec({"mass": "46 g", "radius": "21.3 mm", "u0": "12 m/s", "effects": ["slip-coupling"],
                           "normal": {"model": "half-sine", "contact_time": "500 us", "normal_speed": "24 m/s",
                                      "restitution": 0.6}}, "impact", "imp.toml")
    assert isinstance(imp.normal, HalfSineNormal)
    assert imp.normal.impulse == pytest.approx(0.046 * 24 * 1.6) and imp.normal.contact_time == pytest.approx(500e-6)
    assert imp.duration == pytest.approx(500e-6)  # taken from the normal pulse


@pytest.mark.parametrize("spec, match", [
    ({"mass": "46 g", "u0": "1 m/s", "duration": "1 s", "effects": ["spin"]}, "missing 'radius'"),
    ({"mass": "46 g", "u0": "1 m/s", "duration": "1 s", "effects": ["magic"]}, "unknown effect"),
    ({"mass": "46 g", "u0": "1 m/s", "duration": "1 s", "effects": ["compliance"]}, "linear' with stiffness and damping"),
    ({"mass": "46", "u0": "1 m/s", "duration": "1 s"}, "scene.mass"),
    ({"mass": "46 g", "u0": "1 m/s"}, "needs 'duration'"),
    ({"mass": "46 g", "u0": "1 m/s", "duration": "1 s", "area": {"model": "column"}}, "time column"),
])
def test_scene_spec_errors_name_the_field(spec, match):
    with pytest.raises(Exception, match=match) as err:
        Scene.from_spec(spec, "impact", "bad.toml")
    assert "bad.toml" in str(err.value) and "\n" not in str(err.value)


class _nothing:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False
