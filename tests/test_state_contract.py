"""The state contract: laws with memory declare states and rates; the plan integrates them only for them."""
from __future__ import annotations

import math

import numpy as np
import pytest

import frictionlab as fl
from frictionlab import Contact, FrictionLaw, ParamSpec, StateSpec, make_plan, simulate
from frictionlab.batch import simulate_batch
from frictionlab.errors import LawError, SolverError
from frictionlab.predict import applicable_solvers
from frictionlab.scene import G

from _scenes import incline, normal_impact


class SlipMeter(FrictionLaw):
    """Coulomb friction that also counts the slid distance s (a state the force ignores)."""

    name = "slip-meter"
    formula = "F = mu N sign(u), ds/dt = |u|"
    citation = "test"
    params = (ParamSpec("mu", "", 0.2, 0.0, 5.0, 0.3, "friction coefficient"),)
    requires = frozenset({"u", "N"})
    states = (StateSpec("s", "m", 0.0, 1.0, "slid distance"),)

    def force(self, p, c):
        return p["mu"] * c.N * np.sign(c.u) + 0.0 * c.state["s"]

    def rates(self, p, c):
        return {"s": np.abs(c.u)}


def test_memoryless_plan_is_unchanged_and_stateful_states_are_prefixed():
    scene = normal_impact()
    assert make_plan(scene, fl.get_law("coulomb")).states == ("v", "omega", "theta")
    plan = make_plan(scene, fl.get_law("rate-state-aging"))
    assert plan.states == ("v", "omega", "theta", "law:theta")  # no clash with the spin angle
    assert make_plan(scene, fl.get_law("lugre")).law_states == ("law:z",)
    assert fl.get_law("coulomb").states == () and "states" not in vars(type(fl.get_law("coulomb")))


def test_states_are_integrated_against_the_closed_form():
    """On an incline with mu < tan(alpha) the block accelerates at g (sin a - mu cos a): s = u0 t + a t^2 / 2."""
    law = SlipMeter()
    scene = incline(alpha_deg=20.0, u0=1.0, duration=1.0)
    t = np.linspace(0.0, 1.0, 11)
    tr = simulate(law, scene, {"mu": 0.2}, solver="ode", t=t)
    acc = G * (math.sin(math.radians(20)) - 0.2 * math.cos(math.radians(20)))
    assert np.allclose(tr.law_states["s"], 1.0 * t + 0.5 * acc * t**2, rtol=1e-8, atol=1e-10)
    ref = simulate("coulomb", scene, {"mu": 0.2}, solver="exact", t=t)
    assert np.allclose(tr.v, ref.v, rtol=1e-8)
    assert simulate("coulomb", scene, {"mu": 0.2}, solver="ode", t=t).law_states == {}


def test_initial_steady_state_is_taken_at_the_initial_slip():
    law = fl.get_law("rate-state-slip")
    scene = incline(u0=2.0)
    p = law.defaults()
    plan = make_plan(scene, law)
    y0 = plan.initial_state(p)
    assert y0[plan.index("law:theta")] == pytest.approx(p["Dc"] / 2.0, rel=1e-15)
    with pytest.raises(fl.FrictionLabError, match="needs the parameters"):
        plan.initial_state()


def test_closed_forms_and_batch_do_not_apply_to_stateful_laws():
    scene = normal_impact()
    why = applicable_solvers("lugre", scene)
    assert why["ode"] is None
    assert "internal state (z)" in why["exact"] and "internal state (z)" in why["series"]
    with pytest.raises(SolverError, match=r"batch: law 'lugre' has internal state \(z\)"):
        simulate_batch("lugre", [scene, scene])


def test_derivatives_is_the_one_right_hand_side():
    law = SlipMeter()
    scene = incline(alpha_deg=20.0, u0=1.0)
    plan = make_plan(scene, law)
    p = {"mu": 0.2}
    y = plan.initial_state(p)
    dy = plan.derivatives(p, 0.0, y)
    acc = G * (math.sin(math.radians(20)) - 0.2 * math.cos(math.radians(20)))
    assert dy == pytest.approx([acc, 1.0])


@pytest.mark.parametrize("bad, match", [
    (dict(name="2z"), "identifier"),
    (dict(initial="steadyish"), "'steady'"),
    (dict(initial=float("nan")), "finite SI number"),
    (dict(scale=0.0), "scale must be a positive"),
])
def test_degenerate_state_specs_are_refused(bad, match):
    kw = dict(name="z", unit="m", initial=0.0, scale=1.0, description="d") | bad
    with pytest.raises(LawError, match=match):
        StateSpec(**kw)


def _broken(rates_out, steady=None):
    class Broken(SlipMeter):
        name = "broken-state"
        states = (StateSpec("s", "m", "steady" if steady else 0.0, 1.0, "slid distance"),)

        def rates(self, p, c):
            return rates_out(c)

    if steady:
        Broken.steady_state = lambda self, p, c: steady(c)
    return Broken


@pytest.mark.parametrize("rates_out, steady, match", [
    (lambda c: {"s": np.full(c.u.shape, np.nan)}, None, r"rates\(\)\['s'\] is NaN"),
    (lambda c: {"s": np.ones(2)}, None, r"rates\(\)\['s'\] has shape \(2,\)"),
    (lambda c: {"q": c.u}, None, r"rates\(\) must return a mapping with keys \['s'\]"),
    (lambda c: {"s": c.u}, lambda c: {"s": np.full(c.u.shape, np.inf)}, r"steady_state\(\)\['s'\] is NaN or infinite"),
])
def test_registry_probes_rates_and_names_the_plugin(rates_out, steady, match):
    with pytest.raises(LawError, match=r"law 'broken-state' \(run-time registration of .*Broken\): " + match):
        fl.register_law(_broken(rates_out, steady))


def test_steady_state_missing_is_a_clear_error():
    class NoSteady(SlipMeter):
        name = "no-steady"
        states = (StateSpec("s", "m", "steady", 1.0, "slid distance"),)

    with pytest.raises(LawError, match=r"declares states \['s'\] but does not define steady_state\(\)"):
        fl.register_law(NoSteady)


def test_stateful_law_force_sees_its_state():
    law = fl.get_law("lugre")
    p = law.defaults()
    c = Contact(t=np.zeros(2), u=np.array([1.0, -1.0]), N=np.full(2, 10.0), state={"z": np.array([2e-6, -1e-6])})
    dz = c.u - p["sigma0"] * np.abs(c.u) * c.state["z"] / 0.3  # g(1 m/s) = mu_c for vs = 1 mm/s
    assert law.evaluate_rates(p, c)["z"] == pytest.approx(dz, rel=1e-12)
    assert law.evaluate(p, c) == pytest.approx(10.0 * p["sigma0"] * c.state["z"], rel=1e-12)
