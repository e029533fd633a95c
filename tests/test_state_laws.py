"""The state laws beyond aging and slip (PRZ, Nagata, two-state aging and slip) on velocity steps up and down,
against an independent high-accuracy solve of the published equations in rsfmodel's variables (friction and
states, d mu/dt = k (V_lp - V)), and their reductions: Nagata with c = 0 is the aging law, a two-state law with
b2 = 0 the one-state law."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import frictionlab as fl
from frictionlab.physics.scene import ConstantNormal, Scene, SpringLoad

UM = 1e-6
V0 = 1.0  # um/s, the laws' reference speed
K = {"rate-state-aging2": 3e-3, "rate-state-slip2": 8e-3}  # spring stiffness [1/um] where not 1e-3 (stable sliders)
T = np.arange(0.0, 40.01, 0.25)  # s; the load point steps at t = 10 s
STEPS = {"up": (1.0, 10.0), "down": (10.0, 1.0)}  # um/s

# laboratory units (um, um/s, 1/um) for the reference; the laws take SI
CASES = {
    "rate-state-prz": dict(mu0=0.6, a=0.01, b=0.005, Dc=10.0),
    "rate-state-nagata": dict(mu0=0.6, a=0.027, b=0.029, Dc=3.33, c=2.0),
    "rate-state-aging2": dict(mu0=0.6, a=0.012, b1=0.0185, Dc1=5.0, b2=0.0088, Dc2=50.0),
    "rate-state-slip2": dict(mu0=0.6, a=0.012, b1=0.0185, Dc1=5.0, b2=0.0088, Dc2=50.0),
}


def reference(law: str, p: dict, v1: float, v2: float) -> np.ndarray:
    """Friction at T by solve_ivp (DOP853, rtol 1e-12) of the published equations: mu and each theta (Dc in um)."""
    if law in ("rate-state-aging2", "rate-state-slip2"):
        pairs = [(p["b1"], p["Dc1"]), (p["b2"], p["Dc2"])]
    else:
        pairs = [(p["b"], p["Dc"])]
    scale = 2.0 if law == "rate-state-prz" else 1.0  # PRZ: b ln(V0 theta / (2 Dc)), theta_ss = 2 Dc / V

    def velocity(mu, th):
        return V0 * math.exp((mu - p["mu0"] - sum(b * math.log(V0 * x / (scale * dc)) for (b, dc), x in zip(pairs, th)))
                             / p["a"])

    def rhs(t, y):
        mu, th = y[0], y[1:]
        v = velocity(mu, th)
        dmu = K.get(law, 1e-3) * ((v1 if t < 10.0 else v2) - v)
        out = [dmu]
        for (b, dc), x in zip(pairs, th):
            if law == "rate-state-prz":
                out.append(1.0 - (v * x / (2.0 * dc)) ** 2)
            elif law == "rate-state-nagata":
                out.append(1.0 - v * x / dc - p["c"] / b * x * dmu)
            elif law == "rate-state-slip2":
                out.append(-(v * x / dc) * math.log(v * x / dc))
            else:
                out.append(1.0 - v * x / dc)
        return out

    mu_ss = p["mu0"] + (p["a"] - sum(b for b, _ in pairs)) * math.log(v1 / V0)
    y0 = [mu_ss] + [scale * dc / v1 for _, dc in pairs]
    out = []
    for span, tt in (((0.0, 10.0), T[T <= 10.0]), ((10.0, T[-1]), T[T > 10.0])):  # restarted at the step
        sol = solve_ivp(rhs, span, y0, method="DOP853", t_eval=tt, rtol=1e-12, atol=1e-14, dense_output=True)
        assert sol.success
        out.append(sol.y[0])
        y0 = sol.sol(span[1])
    return np.concatenate(out)


def _si(p: dict) -> dict:
    return {k: v * UM if k.startswith("Dc") else v for k, v in p.items()}


def _scene(v1, v2, k=1e-3):
    return Scene(kind="spring-slider", mass=1.0, u0=v1 * UM, duration=float(T[-1]), normal=ConstantNormal(1e4),
                 spring=SpringLoad(k / UM, (0.0, 10.0), (v1 * UM, v2 * UM)))


@pytest.mark.parametrize("step", sorted(STEPS))
@pytest.mark.parametrize("law", sorted(CASES))
def test_state_laws_follow_the_published_equations_on_steps_up_and_down(law, step):
    v1, v2 = STEPS[step]
    ref = reference(law, CASES[law], v1, v2)
    sim = fl.simulate(law, _scene(v1, v2, K.get(law, 1e-3)), _si(CASES[law]), t=T)
    assert np.max(np.abs(sim.load - ref)) < 1e-6
    assert abs(ref[-1] - ref[0]) > 1e-3  # the step moved the friction: the comparison could fail


@pytest.mark.parametrize("step", sorted(STEPS))
def test_the_general_plan_and_the_fast_path_agree_for_prz_and_nagata(step):
    for law in ("rate-state-prz", "rate-state-nagata"):
        scene, p = _scene(*STEPS[step]), _si(CASES[law])
        fast = fl.simulate(law, scene, p, solver="ode", t=T)
        general = fl.simulate(law, scene, p, solver="ode:LSODA", t=T)
        assert fast.solver == "ode" and general.solver == "ode:LSODA"
        assert np.max(np.abs(fast.load - general.load)) < 1e-7


@pytest.mark.parametrize("solver", ["ode", "ode:LSODA"])
def test_nagata_with_c_0_is_the_aging_law(solver):
    p = _si(dict(CASES["rate-state-nagata"], c=0.0))
    scene = _scene(*STEPS["up"])
    nagata = fl.simulate("rate-state-nagata", scene, p, solver=solver, t=T)
    aging = fl.simulate("rate-state-aging", scene, {k: v for k, v in p.items() if k != "c"}, solver=solver, t=T)
    assert np.array_equal(nagata.load, aging.load)
    with_c = fl.simulate("rate-state-nagata", scene, _si(CASES["rate-state-nagata"]), solver=solver, t=T)
    assert np.max(np.abs(with_c.load - aging.load)) > 1e-3


@pytest.mark.parametrize("evolution", ["aging", "slip"])
def test_a_two_state_law_with_b2_0_is_the_one_state_law(evolution):
    one = dict(mu0=0.6, a=0.012, b=0.0185, Dc=5.0 * UM)
    two = dict(mu0=0.6, a=0.012, b1=0.0185, Dc1=5.0 * UM, b2=0.0, Dc2=50.0 * UM)
    for step in STEPS.values():
        scene = _scene(*step, k=3e-3)
        a = fl.simulate(f"rate-state-{evolution}", scene, one, solver="ode:LSODA", t=T)
        b = fl.simulate(f"rate-state-{evolution}2", scene, two, solver="ode:LSODA", t=T)
        assert np.max(np.abs(a.load - b.load)) < 1e-9
        assert np.max(np.abs(a.law_states["theta"] / b.law_states["theta1"] - 1)) < 1e-6


def test_a_plugin_state_law_reads_dmudt_as_the_built_in_nagata_law_does():
    from frictionlab.laws.rate_state_aging import RateStateAging
    from frictionlab.physics.law import ParamSpec

    class Plugin(RateStateAging):
        name = "test-stress-aged"
        params = RateStateAging.params + (ParamSpec("c", "", 2.0, 0.0, 20.0, 1.0, "stress weakening"),)
        requires = RateStateAging.requires | {"dmudt"}

        def rates(self, p, c):
            theta = c.state["theta"]
            return {"theta": 1.0 - abs(c.u) * theta / p["Dc"] - p["c"] / p["b"] * theta * c.dmudt}

    fl.register_law(Plugin)
    try:
        p = _si(CASES["rate-state-nagata"])
        scene = _scene(*STEPS["down"])
        plugin = fl.simulate("test-stress-aged", scene, p, t=T)
        built_in = fl.simulate("rate-state-nagata", scene, p, solver="ode:LSODA", t=T)
        assert np.max(np.abs(plugin.load - built_in.load)) < 1e-9
    finally:
        fl.unregister_law("test-stress-aged")


def test_where_no_scene_supplies_dmudt_the_law_is_refused_in_one_line():
    from frictionlab.solve.solvers.prescribed import respond

    with pytest.raises(fl.FrictionLabError, match=r"needs dmudt .* a spring-slider supplies it"):
        fl.simulate("rate-state-nagata", fl.load_dataset("incline-oil-a100"))
    with pytest.raises(fl.FrictionLabError, match="prescribed slip history does not supply"):
        respond("rate-state-nagata", {}, np.linspace(0, 1, 5), lambda t: np.full_like(t, 1e-6))
    prz = fl.simulate("rate-state-prz", fl.load_dataset("incline-oil-a100"))  # laws without dmudt go anywhere
    assert np.all(np.isfinite(prz.v))


def _step_target(folder, law: str, truth: dict, seed: int = 11, sigma: float = 2e-4):
    """A synthetic velocity step of ``law`` (the quasi-static kernel at rtol 1e-10, mu_ss = 0.6; truth: a, b, Dc
    [um], c) with white noise of known sigma: the fit's Target."""
    import sys
    from pathlib import Path

    import attrs

    from frictionlab.inference.fitting.predict import Target
    from frictionlab.solve import quasistatic

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    from calibration_ar1 import make_dataset

    ds, _ = make_dataset(folder, "none", True)
    load = quasistatic.Load.of(ds.scene.spring)
    k_um = ds.scene.spring.stiffness * UM
    y = 0.6 + quasistatic.solve(quasistatic.LAWS[law], truth["a"], truth["b"], truth["Dc"], k_um, load, ds.t, 1e-10,
                                c=truth.get("c", 0.0)).m
    y = y + np.random.default_rng(seed).normal(0.0, sigma, y.size)
    data = attrs.evolve(ds, columns=dict(ds.columns, mu=y), noise={"mu": sigma})
    return Target(data, "mu", y, np.full(y.size, sigma))


def test_the_velocity_step_fit_serves_prz_and_recovers_its_truth(tmp_path):
    """PRZ data: the velocity-step fit serves the law, finds a, b, Dc within 3 standard errors of the truth, and the
    aging law fits the same data worse."""
    truth = dict(a=0.009, b=0.012, Dc=8.0)
    target = _step_target(tmp_path, "rate-state-prz", truth)
    prz, aging = fl.fit("rate-state-prz", target), fl.fit("rate-state-aging", target)
    assert prz.ok and prz.velstep is not None and prz.solver == "ode"
    for name, value in truth.items():
        assert abs(prz.value(name) - value * (UM if name == "Dc" else 1.0)) < 3 * prz.stderr(name), name
    assert aging.stats.chisqr > prz.stats.chisqr + 10


def test_the_velocity_step_fit_serves_nagata_and_recovers_c(tmp_path):
    """Nagata data (c = 2): the velocity-step fit serves the law with c fitted (its sensitivity from the kernel),
    finds a, b, Dc and c within two standard errors of the truth, prints c in its table, and the aging law (c = 0)
    fits the same data worse."""
    truth = dict(a=0.009, b=0.012, Dc=8.0, c=2.0)
    target = _step_target(tmp_path, "rate-state-nagata", truth)
    nagata, aging = fl.fit("rate-state-nagata", target), fl.fit("rate-state-aging", target)
    assert nagata.ok and nagata.velstep is not None and nagata.solver == "ode"
    for name, value in truth.items():
        assert abs(nagata.value(name) - value * (UM if name == "Dc" else 1.0)) < 2 * nagata.stderr(name), name
    assert nagata.stderr("c") < 1.0  # c is determined, not merely bounded
    assert any(line.strip().startswith("c ") for line in nagata.velstep.lines())
    assert aging.stats.chisqr > nagata.stats.chisqr + 10


def test_nagata_fitted_on_an_aging_step_gives_c_consistent_with_0_and_with_c_held_at_0_is_the_aging_fit(tmp_path):
    target = _step_target(tmp_path, "rate-state-aging", dict(a=0.009, b=0.012, Dc=8.0), seed=5)
    aging = fl.fit("rate-state-aging", target)
    nagata = fl.fit("rate-state-nagata", target)
    assert nagata.ok and nagata.solver == "ode"
    c, err = nagata.value("c"), nagata.stderr("c")
    assert (err is None and c < 1e-3) or c < 2 * err, (c, err)  # at its bound 0, or within two errors of it
    held = fl.fit("rate-state-nagata", target, fixed={"c": 0.0})
    assert held.ok and held.solver == "ode" and held.value("c") == 0.0
    for name in ("a", "b", "Dc", "mu0"):
        assert held.value(name) == pytest.approx(aging.value(name), rel=1e-6), name
        assert held.stderr(name) == pytest.approx(aging.stderr(name), rel=1e-4), name
    assert held.stats.chisqr == pytest.approx(aging.stats.chisqr, rel=1e-8)


def test_nagata_on_a_slider_with_mass_reads_the_load_rate_and_tends_to_the_quasi_static_slider():
    import attrs

    p = _si(CASES["rate-state-nagata"])
    scene = _scene(*STEPS["up"])
    quasi = fl.simulate("rate-state-nagata", scene, p, t=T)
    gaps = []
    for mass in (1e3, 10.0):
        heavy = attrs.evolve(scene, spring=SpringLoad(scene.spring.stiffness, scene.spring.times,
                                                      scene.spring.velocities, mass=mass))
        gaps.append(np.max(np.abs(fl.simulate("rate-state-nagata", heavy, p, t=T, solver="ode:BDF").load - quasi.load)))
    assert gaps[1] < gaps[0] and gaps[1] < 1e-5
