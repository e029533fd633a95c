"""The state contract: laws with memory declare states and rates; the plan integrates them only for them."""
from __future__ import annotations

import math

import numpy as np
import pytest
from _scenes import incline, normal_impact

import frictionlab as fl
from frictionlab import Contact, FrictionLaw, ParamSpec, StateSpec, make_plan, simulate
from frictionlab.core.errors import LawError, SolverError
from frictionlab.solve.choice import applicable_solvers
from frictionlab.physics.scene import G
from frictionlab.solve.batch import simulate_batch
from frictionlab.solve.solvers.prescribed import respond


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


STATEFUL_PLUGIN = """
    import numpy as np
    from frictionlab import FrictionLaw, ParamSpec, StateSpec

    class Relaxing(FrictionLaw):
        name = "relaxing-third-party"
        formula = "F = m N, dm/dt = (mu sign(u) - m) |u| / L"
        citation = "a third-party package"
        params = (ParamSpec("mu", "", 0.3, 0.0, 5.0, 0.3, "steady friction coefficient"),
                  ParamSpec("L", "m", 0.5, 1e-6, 10.0, 0.1, "memory length"))
        requires = frozenset({"u", "N"})
        states = (StateSpec("m", "", 0.0, 0.3, "friction coefficient carried"),)

        def force(self, p, c):
            return c.state["m"] * c.N

        def rates(self, p, c):
            return {"m": (p["mu"] * np.sign(c.u) - c.state["m"]) * np.abs(c.u) / p["L"]}
"""


@pytest.fixture
def stateful_plugin(tmp_path, monkeypatch):
    from test_registry import installed_plugin

    yield from installed_plugin(tmp_path, monkeypatch, "relaxing-law", STATEFUL_PLUGIN,
                                "relaxing-third-party = relaxing_law:Relaxing\n")


def test_third_party_stateful_law_works_as_a_builtin(stateful_plugin, run_cli):
    """Registered by an entry point; integrated by the plan; listed with its state; joins 'all' only."""
    from frictionlab.pipeline.comparison import DEFAULT_LAWS, select_laws

    law = fl.get_law("relaxing-third-party")
    # a block sliding at constant speed (no drive, huge mass): m(x) = mu (1 - exp(-x / L)), x = u0 t
    scene = fl.Scene(kind="incline", mass=1e12, u0=1.0, duration=2.0, normal=fl.physics.scene.WeightNormal(10.0))
    t = np.linspace(0.0, 2.0, 9)
    tr = simulate(law, scene, {"mu": 0.3, "L": 0.5}, t=t)
    assert tr.solver == "ode:LSODA"
    assert np.allclose(tr.law_states["m"], 0.3 * (1 - np.exp(-t / 0.5)), rtol=1e-7, atol=1e-12)
    assert np.allclose(tr.force, 10.0 * tr.law_states["m"], rtol=1e-12)
    assert "relaxing-third-party" not in select_laws(None) and select_laws(None) == DEFAULT_LAWS
    assert "relaxing-third-party" in select_laws("all") and "lugre" in select_laws(["all"])
    out = run_cli("laws", env={"PYTHONPATH": str(stateful_plugin)})
    assert out.returncode == 0, out.stderr
    block = out.stdout.split("relaxing-third-party:")[1].split("\n\n")[0]
    assert "relaxing-law 0.1" in block and "internal states" in block and "friction coefficient carried" in block


def test_laws_command_lists_the_builtin_states(run_cli):
    out = run_cli("laws", "--brief")
    assert out.returncode == 0, out.stderr
    rows = {line.split()[0]: line for line in out.stdout.splitlines()[2:]}
    for name, state in (("lugre", "z"), ("dahl", "mu_d"), ("rate-state-aging", "theta"), ("rate-state-slip", "theta")):
        assert rows[name].rstrip().endswith(state)
    assert rows["stribeck"].rstrip().endswith("-") and rows["coulomb"].rstrip().endswith("-")


def _readme_stateful_code() -> str:
    import re
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "docs" / "guides" / "registering-a-law.md").read_text()
    block = re.search(r"```python\n(import numpy as np\n\nfrom frictionlab import FrictionLaw, ParamSpec, StateSpec.*?)```",
                      text, re.S)
    assert block, "the law guide has no stateful law example"
    return block.group(1)


def test_readme_stateful_law_example_runs_as_written():
    code = _readme_stateful_code()
    assert len(code.splitlines()) <= 30
    exec(compile(code, "my_stateful_law.py", "exec"), {})
    try:
        # sliding at a constant 1 m/s (no drive, huge mass), started in steady state
        scene = fl.Scene(kind="incline", mass=1e12, u0=1.0, duration=1e-2, normal=fl.physics.scene.WeightNormal(10.0))
        tr = simulate("lagged-coulomb", scene, {"mu": 0.3, "L": 1e-3}, t=np.linspace(0, 1e-2, 5))
        assert np.allclose(tr.force, 3.0, rtol=1e-9)  # started steady, stays steady
        F, s = respond("lagged-coulomb", {"mu": 0.3, "L": 1e-3}, np.linspace(0, 4e-3, 5),
                       lambda t: np.where(np.asarray(t) < 2e-3, 1.0, -1.0), N=10.0)
        assert F[2] == pytest.approx(3.0) and F[4] == pytest.approx(-3.0 + 6.0 * math.exp(-2.0), rel=1e-6)
    finally:
        fl.unregister_law("lagged-coulomb")


def test_rate_state_sticks_at_zero_slip_with_its_state_held():
    """Rate-and-state's force turns over within ~1e-30 m/s of zero slip: it declares jumps_at_zero_slip,
    so the ball rolls (slip 0) once slip reaches zero, and theta is held while it does."""
    law = fl.get_law("rate-state-aging")
    assert law.jumps_at_zero_slip and not fl.get_law("lugre").jumps_at_zero_slip
    tr = simulate(law, normal_impact(), solver="ode", t=np.linspace(0.0, 500e-6, 51))
    assert tr.stick_time is not None and 0 < tr.stick_time < 500e-6
    after = tr.t > tr.stick_time
    assert np.all(tr.u[after] == 0.0)
    assert np.ptp(tr.law_states["theta"][after]) == 0.0
    assert make_plan(normal_impact(), fl.get_law("lugre")).continuous


def test_plugin_with_a_degenerate_state_spec_is_skipped_naming_it(tmp_path, monkeypatch):
    from test_registry import _write_dist

    from frictionlab.physics import registry

    bad = STATEFUL_PLUGIN.replace('StateSpec("m", "", 0.0, 0.3,', 'StateSpec("m", "", 0.0, 0.0,')
    _write_dist(tmp_path, "degenerate-law", bad, "degenerate = degenerate_law:Relaxing\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    try:
        with pytest.warns(registry.PluginWarning,
                          match=r"entry point 'degenerate = degenerate_law:Relaxing' of degenerate-law 0.1: "
                                r"state m: scale must be a positive"):
            registry.reload_registry()
        assert "lugre" in fl.available_laws() and "relaxing-third-party" not in fl.available_laws()
    finally:
        monkeypatch.undo()
        registry.reload_registry()
