"""Laws with memory checked against closed forms and known behaviour (Marone 1998; Canudas de Wit 1995; Dahl 1968)."""
from __future__ import annotations

import math

import numpy as np
import pytest

import frictionlab as fl
from frictionlab.core.errors import SolverError
from frictionlab.io.datagen.springslider import TRUTH
from frictionlab.physics.scene import ConstantNormal, Scene, SpringLoad
from frictionlab.solve.solvers.prescribed import respond

N = 1e4
RS = dict(TRUTH)  # mu0 0.6, a 0.008, b 0.012, Dc 10 um (V0 = 1 um/s): k_c = (b - a)/Dc = 400 /m
V0 = 1e-6
K_C = (RS["b"] - RS["a"]) / RS["Dc"]


def slider(k, times, velocities, T):
    return Scene(kind="spring-slider", mass=1.0, u0=velocities[0], duration=T, normal=ConstantNormal(N),
                 spring=SpringLoad(k, times, velocities))


@pytest.mark.parametrize("law", ["rate-state-aging", "rate-state-slip"])
def test_steady_state_after_a_velocity_step(law):
    """mu_ss = mu0 + (a - b) ln(V/V0) once the slider has slid many Dc at the new speed."""
    t = np.array([0.0, 4.99, 30.0])
    tr = fl.simulate(law, slider(5 * K_C, (0.0, 5.0), (1e-6, 1e-5), 30.0), RS, solver="ode", t=t)
    for mu, V in ((tr.load[1], 1e-6), (tr.load[2], 1e-5)):  # 250 Dc slid at 10 um/s
        assert mu == pytest.approx(RS["mu0"] + (RS["a"] - RS["b"]) * math.log(V / V0), abs=1e-9)
    assert tr.law_states["theta"][2] == pytest.approx(RS["Dc"] / 1e-5, rel=1e-7)


def _healing(law, holds):
    """Peak friction on reloading after each hold, above the steady sliding friction before it."""
    out = []
    for th in holds:
        T = 20.0 + th + 10.0
        t = np.concatenate([[0.0, 19.9], 20.0 + th + np.linspace(0.0, 10.0, 2001)])
        tr = fl.simulate(law, slider(5 * K_C, (0.0, 20.0, 20.0 + th), (1e-5, 0.0, 1e-5), T), RS, solver="ode", t=t)
        out.append(tr.load[2:].max() - tr.load[1])
    return np.array(out)


def test_aging_law_heals_as_log_hold_time_and_slip_law_heals_less():
    holds = np.array([3.0, 10.0, 30.0, 100.0])
    dmu = _healing("rate-state-aging", holds)
    slope, icpt = np.polyfit(np.log(holds), dmu, 1)
    resid = dmu - (slope * np.log(holds) + icpt)
    assert 0.5 * RS["b"] < slope < 1.1 * RS["b"]  # the healing rate beta of the aging law is of order b
    assert np.max(np.abs(resid)) < 0.05 * (dmu[-1] - dmu[0])  # linear in ln(t_hold)
    slip = _healing("rate-state-slip", holds[[0, -1]])
    assert slip[1] - slip[0] < 0.5 * (dmu[-1] - dmu[0])


def test_lugre_steady_state_is_its_stribeck_curve():
    lugre = fl.get_law("lugre")
    p = dict(lugre.defaults(), sigma1=0.01, sigma2=0.05)
    stribeck = fl.get_law("stribeck")
    ps = {k: p[k] for k in stribeck.param_names}
    for u in (-3e-3, -1e-4, 2e-4, 1e-3, 2e-3, 0.5):
        t = np.linspace(0.0, 2e-4 / abs(u) * 5 + 1e-3, 50)
        F, states = respond(lugre, dict(p), t, lambda tt, u=u: np.full(np.shape(tt), u), N=N)
        # started far from steady (z = 0): the bristles relax to the Stribeck curve
        c = fl.Contact(t=t[-1:], u=np.array([u]), N=np.array([N]))
        assert F[-1] == pytest.approx(stribeck.force(ps, c)[0], rel=1e-7)


def test_dahl_hysteresis_loop_closes_with_the_closed_form_area():
    """Under x = X sin(w t) the loop closes; for alpha = 1 its area is 4 X Fc - 2 (Fc + Fm)(Fc/s)(1 - E)
    with E = exp(-2 s X / Fc), Fm = Fc (1 - E)/(1 + E) (s = sigma N, Fc = mu_c N)."""
    p = {"mu_c": 0.3, "sigma": 1e4, "alpha": 1.0}
    X, w = 1e-4, 2 * math.pi
    t = np.linspace(0.0, 4.0, 4001)
    F, states = respond("dahl", p, t, lambda tt: X * w * np.cos(w * tt), N=N)
    last, prev = F[3000:], F[2000:3001]
    assert np.max(np.abs(last - prev)) < 1e-6 * N * p["mu_c"]  # the loop closes: period 4 equals period 3
    x = X * np.sin(w * t[3000:])
    area = abs(np.trapezoid(F[3000:], x))
    Fc, s = p["mu_c"] * N, p["sigma"] * N
    E = math.exp(-2 * s * X / Fc)
    Fm = Fc * (1 - E) / (1 + E)
    exact = 4 * X * Fc - 2 * (Fc + Fm) * (Fc / s) * (1 - E)
    assert area == pytest.approx(exact, rel=1e-4)
    assert area > 0.1 * 4 * X * Fc  # a real loop, not a line


def _growth(k, law="rate-state-aging"):
    """Ratio of late to early oscillation amplitude of mu after a 5 % velocity step (>1: growing; inf: the
    oscillation grew into stick-slip, which the quasi-static slider reports as an error)."""
    T = 120.0
    t = np.linspace(0.0, T, 2401)
    try:
        tr = fl.simulate(law, slider(k, (0.0, 1.0), (1e-5, 1.05e-5), T), RS, solver="ode", t=t)
    except SolverError as exc:
        assert "unstable slider" in str(exc)
        return math.inf
    mu = tr.load - (RS["mu0"] + (RS["a"] - RS["b"]) * math.log(1.05e-5 / V0))
    early, late = np.abs(mu[(t > 10) & (t < 40)]).max(), np.abs(mu[t > 90]).max()
    return late / early


def test_spring_slider_is_stable_above_the_critical_stiffness_and_not_below():
    assert _growth(1.2 * K_C) < 0.5
    assert _growth(0.85 * K_C) > 2.0


def test_critical_stiffness_found_by_bisection():
    lo, hi = 0.85 * K_C, 1.2 * K_C
    for _ in range(4):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if _growth(mid) < 1.0 else (mid, hi)
    k_found = 0.5 * (lo + hi)
    assert k_found == pytest.approx(K_C, rel=0.03)


# --- fitted: each rate-and-state law recovered from its own velocity steps; told apart where the data can ---
@pytest.fixture(scope="module")
def rs_fits():
    return {(law, ds): fl.fit(law, ds) for ds in ("spring-slider-aging", "spring-slider-slip", "spring-slider-small-step")
            for law in ("rate-state-aging", "rate-state-slip")}


@pytest.mark.slow
@pytest.mark.parametrize("law, ds", [("rate-state-aging", "spring-slider-aging"), ("rate-state-slip", "spring-slider-slip")])
def test_rate_state_law_recovered_from_its_own_velocity_steps(rs_fits, law, ds):
    r = rs_fits[(law, ds)]
    assert r.ok, r.reason
    for name in ("mu0", "a", "b", "Dc"):
        p = r.params[name]
        assert abs(p.value - RS[name]) < max(4 * p.stderr, 1e-3 * abs(RS[name])), (name, p.value, p.stderr)
    assert 0.8 < r.stats.redchi < 1.25


@pytest.mark.slow
def test_aging_and_slip_told_apart_by_large_steps_not_by_small_ones(rs_fits):
    def delta_aic(ds, right, wrong):
        return rs_fits[(wrong, ds)].stats.aic - rs_fits[(right, ds)].stats.aic

    assert delta_aic("spring-slider-aging", "rate-state-aging", "rate-state-slip") > 10
    assert delta_aic("spring-slider-slip", "rate-state-slip", "rate-state-aging") > 10
    # a 10 % step: both laws fit equally well (they agree to first order about steady sliding)
    assert abs(delta_aic("spring-slider-small-step", "rate-state-aging", "rate-state-slip")) < 2


def test_memoryless_laws_on_a_spring_slider():
    """A viscous law drives the quasi-static slider (mu = c A v / N relaxes to the new speed at rate k N/(c A));
    Coulomb has no slip-rate dependence and is refused with the reason."""
    from frictionlab.physics.scene import ConstantArea

    scene = slider(2000.0, (0.0, 1.0), (1e-6, 2e-6), 3.0).with_(area=ConstantArea(1e-3))
    c = 0.6 * N / (1e-3 * 1e-6)  # wear law lam: mu = 0.6 at 1 um/s
    t = np.linspace(1.0, 3.0, 9)
    tr = fl.simulate("wear", scene, {"lam": c}, t=np.concatenate([[0.0], t]))
    rate = 2000.0 * N / (c * 1e-3)
    assert np.allclose(tr.load[1:], 0.6 * (2 - np.exp(-rate * (t - 1.0))), rtol=1e-7)
    with pytest.raises(fl.FrictionLabError, match="does not grow with the slip rate"):
        fl.simulate("coulomb", scene, {"mu": 0.6})


def test_a_law_whose_force_ignores_the_slip_rate_is_refused_by_the_plan_and_skipped_by_a_fit():
    """Dahl's force depends on its state only (dF/du = 0 at fixed state, whatever its parameters): the plan
    refuses it on a spring-slider up front, so a fit is 'skipped' with that reason, not a failed search."""
    from frictionlab.io.dataset import load_dataset
    from frictionlab.physics.registry import get_law
    from frictionlab.solve.plan import make_plan

    ds = load_dataset("spring-slider-aging")
    with pytest.raises(fl.FrictionLabError, match="'dahl' on a spring-slider: its force does not grow"):
        make_plan(ds.scene, get_law("dahl"))
    make_plan(ds.scene, get_law("rate-state-aging"))  # a direct effect a > 0: accepted
    res = fl.fit("dahl", ds)
    assert res.status == "skipped" and "does not grow with the slip rate" in res.reason


def test_report_figures_survive_a_curve_the_solver_cannot_draw(monkeypatch):
    """A stiff law's dense best-fit curve may exceed the ODE budget: the figure keeps the fitted points."""
    from frictionlab.inference.fitting.fit import DatasetFit
    from frictionlab.report import figures

    ds = fl.load_dataset("incline-oil-a100")
    f = fl.fit("couette", ds, solver="exact")

    def refuse(self, *a, **k):
        raise SolverError("ode:LSODA: needed more than 50000 right-hand-side evaluations")

    monkeypatch.setattr(DatasetFit, "trajectory", refuse)
    assert figures.fit_figure(ds, [f], []).startswith(b"\x89PNG")
    assert figures.force_figure(ds, [f]).startswith(b"\x89PNG")


def test_ode_only_laws_skip_impact_outcome_sets_by_default_but_fit_when_the_solver_is_named():
    """`compare --laws all` stays minutes, not hours: an ODE-only law on an impact-outcome set (every
    evaluation simulates every impact) is a skipped candidate with the reason, unless the solver is named."""
    from frictionlab.pipeline.comparison import candidates

    outcome = fl.load_dataset("impact-outcome-synthetic")
    (solver, why), = candidates("lugre", outcome, None)
    assert solver == "ode" and "--solver ode" in why
    assert candidates("lugre", outcome, ["ode"]) == [("ode", None)]
    assert candidates("coulomb", outcome, None) == [("exact", None)]  # closed forms are fitted as before
    assert candidates("lugre", fl.load_dataset("incline-dry-d10"), None) == [("ode", None)]
