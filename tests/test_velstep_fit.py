"""The velocity-step fit (inference.velstep.fit) and its quasi-static integrator (solve.quasistatic): against the
general plan, against finite differences, against a brute-force joint fit, and what it says at a bound."""
from __future__ import annotations

import math
import sys
import tempfile
from fractions import Fraction
from pathlib import Path

import attrs
import numpy as np
import pytest

import frictionlab as fl
from frictionlab.core.errors import ParameterError
from frictionlab.inference.fitting.predict import Target
from frictionlab.physics.scene import ConstantNormal, Scene, SpringLoad
from frictionlab.solve import quasistatic
from frictionlab.solve import quasistatic_kernel as kernel

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

LAWS = ("rate-state-aging", "rate-state-slip")
RS = {"mu0": 0.6, "a": 0.008, "b": 0.012, "Dc": 1e-5}


def test_sdirk4_coefficients_have_order_4_and_an_order_3_embedding():
    F = Fraction
    A = [[F(1, 4)], [F(1, 2), F(1, 4)], [F(17, 50), F(-1, 25), F(1, 4)],
         [F(371, 1360), F(-137, 2720), F(15, 544), F(1, 4)], [F(25, 24), F(-49, 48), F(125, 16), F(-85, 12), F(1, 4)]]
    A = [r + [F(0)] * (5 - len(r)) for r in A]
    assert [float(x) for x in A[1][:1]] == [kernel.A10] and float(A[4][3]) == kernel.A43
    assert [list(row) for row in kernel.TABLEAU] == [[float(A[i][j]) if j < i else 0.0 for j in range(4)]
                                                      for i in range(5)]
    b, bhat = A[4], [F(59, 48), F(-17, 96), F(225, 32), F(-85, 12), F(0)]
    assert [float(x - y) for x, y in zip(b, bhat)] == pytest.approx([kernel.E0, kernel.E1, kernel.E2, kernel.E3,
                                                                      kernel.E4], abs=1e-15)
    c = [sum(r) for r in A]

    def conditions(w):
        Ac = [sum(A[i][j] * c[j] for j in range(5)) for i in range(5)]
        S = lambda v: sum(w[i] * v[i] for i in range(5))  # noqa: E731
        return [S([1] * 5), S(c), S([x * x for x in c]), S(Ac), S([x ** 3 for x in c]),
                S([c[i] * Ac[i] for i in range(5)]), S([sum(A[i][j] * c[j] ** 2 for j in range(5)) for i in range(5)]),
                S([sum(A[i][j] * Ac[j] for j in range(5)) for i in range(5)])]

    assert conditions(b) == [1, F(1, 2), F(1, 3), F(1, 6), F(1, 4), F(1, 8), F(1, 12), F(1, 24)]
    assert conditions(bhat)[:4] == [1, F(1, 2), F(1, 3), F(1, 6)] and conditions(bhat)[4] != F(1, 4)


@pytest.mark.parametrize("law", [kernel.AGING, kernel.SLIP, kernel.PRZ, kernel.NAGATA])
def test_kernel_jacobian_and_parameter_derivatives_match_finite_differences(law):
    p = dict(a=0.009, b=0.011, Dc=7.0, k=0.008, c=2.0, V1=3.0, vlp=10.0)
    f, J, Fp = np.zeros(2), np.zeros((2, 2)), np.zeros((2, 5))

    def rates(m, psi, a=p["a"], b=p["b"], Dc=p["Dc"], k=p["k"], c=p["c"]):
        out = np.zeros(2)
        kernel.rates(law, a, b, Dc, k, c, p["V1"], p["vlp"], m, psi, out, np.zeros((2, 2)), np.zeros((2, 5)))
        return out

    y = (0.004, -0.3)
    kernel.rates(law, p["a"], p["b"], p["Dc"], p["k"], p["c"], p["V1"], p["vlp"], *y, f, J, Fp)
    h = 1e-7
    for j in range(2):
        e = np.eye(2)[j] * h
        fd = (rates(y[0] + e[0], y[1] + e[1]) - rates(y[0] - e[0], y[1] - e[1])) / (2 * h)
        assert J[:, j] == pytest.approx(fd, rel=1e-6, abs=1e-9)
    for j, name in enumerate(("a", "b", "Dc", "k", "c")):  # c: Nagata's (no effect on the other laws)
        hh = 1e-6 * p[name]
        up, dn = rates(*y, **{name: p[name] + hh}), rates(*y, **{name: p[name] - hh})
        assert Fp[:, j] == pytest.approx((up - dn) / (2 * hh), rel=1e-5, abs=1e-9)
    assert (law == kernel.NAGATA) == (abs(Fp[1, 4]) > 0)
    assert quasistatic.LAWS == {"rate-state-aging": kernel.AGING, "rate-state-slip": kernel.SLIP,
                                "rate-state-prz": kernel.PRZ, "rate-state-nagata": kernel.NAGATA}


@pytest.mark.parametrize("law", LAWS + ("rate-state-prz", "rate-state-nagata"))
def test_sensitivities_are_the_derivatives_of_the_computed_solution(law):
    load = quasistatic.Load(np.array([0.0, 20.0]), np.array([3.0, 10.0]))
    t = np.linspace(0.0, 60.0, 1500)
    code = quasistatic.LAWS[law]
    p = np.array([0.009, 0.0095, 7.0, 0.008])
    sol = quasistatic.solve(code, *p, load, t, 1e-11, sensitivities=True, c=1.5)
    assert np.array_equal(sol.m, quasistatic.solve(code, *p, load, t, 1e-11, c=1.5).m)  # S does not steer the steps
    S = sol.S
    assert S.shape[1] == (5 if law == "rate-state-nagata" else 4)  # Nagata's: dm/dc in the fifth column
    p = np.append(p, 1.5)
    for j in range(S.shape[1]):
        h = 1e-6 * p[j]
        up, dn = p.copy(), p.copy()
        up[j] += h
        dn[j] -= h
        fd = (quasistatic.solve(code, *up[:4], load, t, 1e-11, c=up[4]).m
              - quasistatic.solve(code, *dn[:4], load, t, 1e-11, c=dn[4]).m) / (2 * h)
        assert np.max(np.abs(S[:, j] - fd)) <= 1e-4 * np.max(np.abs(fd))


def _slider(times, velocities, k=2000.0, T=300.0):
    return Scene(kind="spring-slider", mass=1.0, u0=velocities[0], duration=T, normal=ConstantNormal(1e4),
                 spring=SpringLoad(k, times, velocities))


@pytest.mark.parametrize("law", LAWS + ("rate-state-prz", "rate-state-nagata"))
@pytest.mark.parametrize("schedule", [((0.0, 5.0, 25.0), (1e-6, 1e-5, 1e-6)), ((0.0, 50.0, 150.0), (1e-6, 0.0, 1e-6))],
                         ids=["steps", "slide-hold-slide"])
def test_fast_path_integrates_as_the_general_plan(law, schedule):
    """solver 'ode' (the quasi-static integrator) against 'ode:LSODA' (the general plan, numerical force partials;
    Nagata's d mu/dt the spring's load rate from the scene): friction, slip rate and state through velocity steps
    and a hold."""
    scene = _slider(*schedule)
    t = np.linspace(0.0, 300.0, 1201)
    p = dict(RS, c=1.0) if law == "rate-state-nagata" else RS
    fast = fl.simulate(law, scene, p, solver="ode", t=t)
    general = fl.simulate(law, scene, p, solver="ode:LSODA", t=t)
    assert fast.solver == "ode" and general.solver == "ode:LSODA"
    assert np.max(np.abs(fast.load - general.load)) < 1e-8
    assert np.max(np.abs(fast.v - general.v) / np.maximum(general.v, 1e-12)) < 1e-5
    assert np.max(np.abs(fast.law_states["theta"] / general.law_states["theta"] - 1)) < 1e-5
    assert np.allclose(fast.force, fast.load * 1e4)


def test_fast_path_refuses_a_runaway_as_the_general_plan_does():
    scene = _slider((0.0, 5.0), (1e-6, 1e-5), k=100.0, T=60.0)  # k far below k_c = (b - a)/Dc = 400 /m
    with pytest.raises(fl.FrictionLabError, match="critical stiffness"):
        fl.simulate("rate-state-aging", scene, RS, solver="ode", t=np.linspace(0, 60, 50))


def test_fast_path_serves_only_built_in_rate_and_state_on_a_quasi_static_slider():
    law = fl.get_law("rate-state-aging")
    assert quasistatic.applies(law, _slider((0.0, 5.0), (1e-6, 1e-5))) == ""
    assert "mass" in quasistatic.applies(law, attrs.evolve(_slider((0.0, 5.0), (1e-6, 1e-5)), spring=SpringLoad(
        2000.0, (0.0, 5.0), (1e-6, 1e-5), mass=1.0)))
    assert "rest" in quasistatic.applies(law, _slider((0.0, 5.0), (0.0, 1e-5)))
    assert "built-in" in quasistatic.applies(fl.get_law("lugre"), _slider((0.0, 5.0), (1e-6, 1e-5)))


@pytest.fixture(scope="module")
def small_step_fits():
    ds = fl.load_dataset("spring-slider-small-step")
    return fl.fit("rate-state-aging", ds), fl.fit("rate-state-aging", ds, solver="ode:LSODA")


def test_velocity_step_fit_agrees_with_the_general_fit(small_step_fits):
    """The fast path (variable projection, sensitivities) and the general lmfit path on a built-in synthetic set:
    the same minimum (values within 0.05 standard errors), the fast one no higher."""
    fast, general = small_step_fits
    assert fast.velstep is not None and general.velstep is None
    assert fast.stats.chisqr <= general.stats.chisqr + 1e-3
    for name in ("mu0", "a", "b", "Dc"):
        assert abs(fast.value(name) - general.value(name)) < 0.05 * fast.stderr(name), name
    assert fast.params["spring.stiffness"].vary is False  # synthetic data: the stiffness is the dataset's


def test_velocity_step_error_bars_are_those_of_the_exact_jacobian(small_step_fits):
    """The reported standard errors equal (J'J)^-1 of a central-difference Jacobian of fl.simulate at rtol 1e-12."""
    fast, _ = small_step_fits
    ds = fl.load_dataset("spring-slider-small-step")
    p0 = {k: fast.value(k) for k in ("mu0", "a", "b", "Dc")}
    cols = []
    for k in p0:
        h = 1e-5 * abs(p0[k])
        up, dn = dict(p0), dict(p0)
        up[k] += h
        dn[k] -= h
        cols.append((fl.simulate("rate-state-aging", ds, up, rtol=1e-12).load
                     - fl.simulate("rate-state-aging", ds, dn, rtol=1e-12).load) / (2 * h))
    J = np.array(cols).T / ds.sigma
    se = np.sqrt(np.diag(np.linalg.inv(J.T @ J)))
    assert [fast.stderr(k) for k in p0] == pytest.approx(se, rel=2e-3)


def _measured_like(tmp, correlation="none", quick=True):
    from calibration_ar1 import make_dataset

    return make_dataset(Path(tmp), correlation, quick)


def test_variable_projection_equals_a_brute_force_joint_fit():
    """mu0 and the trend solved inside each evaluation give the minimum and the covariance of a plain joint
    least-squares fit of all six parameters (a, b, Dc, k, mu0, trend) by scipy."""
    from scipy.optimize import least_squares

    with tempfile.TemporaryDirectory() as tmp:
        ds, curve = _measured_like(tmp)
    y = curve + np.random.default_rng(4).normal(0.0, 4e-4, curve.size)
    data = attrs.evolve(ds, columns=dict(ds.columns, mu=y), noise={"mu": 4e-4})
    f = fl.fit("rate-state-aging", Target(data, "mu", y, np.full(y.size, 4e-4)), trend=True, stiffness=True)
    t, x = data.t, data.columns["x"] * 1e6
    load = quasistatic.Load.of(data.scene.spring)
    x_ref = float(np.interp(load.times[1], t, x))

    def res(th):  # a, b, ln Dc [um], ln k [1/um], mu_ss, trend [1/um]
        m = quasistatic.solve(0, th[0], th[1], math.exp(th[2]), math.exp(th[3]), load, t, 1e-10).m
        return (th[4] + m + th[5] * (x - x_ref) - y) / 4e-4

    v = f.velstep.rows[0].quantities
    mu_ss = f.value("mu0") + (f.value("a") - f.value("b")) * math.log(load.V1)
    start = [f.value("a") * 1.05, f.value("b") * 0.95, math.log(v["Dc"].value * 1.1), math.log(v["k"].value * 0.9),
             mu_ss, v["trend"].value]
    r = least_squares(res, start, x_scale=[1e-3, 1e-3, 1.0, 1.0, 1e-4, 1e-6], method="lm", xtol=1e-14, ftol=1e-14)
    assert 2 * r.cost == pytest.approx(f.stats.chisqr, rel=1e-7)
    cov = np.linalg.inv(r.jac.T @ r.jac)
    brute = {"a": (r.x[0], cov[0, 0]), "b": (r.x[1], cov[1, 1]), "Dc": (math.exp(r.x[2]) * 1e-6, cov[2, 2]),
             "spring.stiffness": (math.exp(r.x[3]) * 1e6, cov[3, 3]), "trend": (r.x[5] * 1e6, cov[5, 5])}
    for name, (value, var) in brute.items():
        p = f.params[name]
        se = math.sqrt(var) * (value if name in ("Dc", "spring.stiffness") else (1e6 if name == "trend" else 1.0))
        assert abs(p.value - value) < 1e-3 * se, name
        assert p.stderr == pytest.approx(se, rel=1e-3), name


def test_trend_and_stiffness_are_fitted_by_default_on_measured_data_only(tmp_path):
    ds, curve = _measured_like(tmp_path)
    y = curve + np.random.default_rng(5).normal(0.0, 4e-4, curve.size)
    synthetic = attrs.evolve(ds, columns=dict(ds.columns, mu=y), noise={"mu": 4e-4})
    measured = attrs.evolve(synthetic, provenance=attrs.evolve(ds.provenance, kind="measured"))
    f_syn = fl.fit("rate-state-aging", Target(synthetic, "mu", y, np.full(y.size, 4e-4)))
    f_meas = fl.fit("rate-state-aging", Target(measured, "mu", y, np.full(y.size, 4e-4)))
    assert "trend" not in f_syn.params and not f_syn.params["spring.stiffness"].vary
    assert "trend" in f_meas.params and f_meas.params["spring.stiffness"].vary
    assert f_meas.stats.chisqr < f_syn.stats.chisqr - 20  # the data have a trend: chi-square falls by far more than 2
    with pytest.raises(ParameterError, match="velocity-step fit only"):
        fl.fit("wear", "impact-golf-v28", trend=True)


def test_a_strengthening_evolution_ends_at_b_0_and_says_so(tmp_path):
    """Data of a negative b (friction keeps rising after an up-step): b ends at its bound 0 with what that means,
    and the diagnostic refit lets b go negative and finds it."""
    ds, _ = _measured_like(tmp_path)
    load = quasistatic.Load.of(ds.scene.spring)
    y = 0.6 + quasistatic.solve(0, 0.01, -0.004, 10.0, 0.008, load, ds.t, 1e-10).m
    y = y + np.random.default_rng(3).normal(0.0, 2e-4, y.size)
    data = attrs.evolve(ds, columns=dict(ds.columns, mu=y), noise={"mu": 2e-4})
    f = fl.fit("rate-state-aging", Target(data, "mu", y, np.full(y.size, 2e-4)))
    assert f.ok and f.value("b") == 0.0 and "b" in f.identifiability.at_bounds
    assert any("b at 0: the evolution runs the other way; a single-state law cannot follow it" in w
               for w in f.identifiability.warnings)
    assert f.stderr("b") is None and f.stderr("a") is not None
    found = [m for m in f.velstep.missing if "strengthening" in m]
    assert found and "b = -0.004" in found[0]


def test_the_strengthening_refit_starts_where_the_bound_held_b(tmp_path):
    """The search keeps its grid points whose a, b fit ended with b held at 0, best first and distinct; a fit that
    ends with b inside its range and no such grid point runs no refit (from there the bound did not act)."""
    from frictionlab.inference.velstep import fit as velstep
    from frictionlab.inference.velstep import missing as velstep_missing

    ds, _ = _measured_like(tmp_path)
    load = quasistatic.Load.of(ds.scene.spring)
    y = 0.6 + quasistatic.solve(0, 0.01, -0.004, 10.0, 0.008, load, ds.t, 1e-10).m
    y = y + np.random.default_rng(3).normal(0.0, 2e-4, y.size)
    data = attrs.evolve(ds, columns=dict(ds.columns, mu=y), noise={"mu": 2e-4})
    law = fl.get_law("rate-state-aging")
    problem = velstep.make_problem(law, [Target(data, "mu", y, np.full(y.size, 2e-4))], {}, {}, {}, None, None, 1e-8)
    (starts,) = problem.search(3)  # one group: the aging law has no extra parameter to start at its bound
    ib = next(i for i, p in enumerate(problem.params) if p.key == "b")
    assert problem.b_held and all(x[ib] == problem.params[ib].bounds_x[0] for x in problem.b_held)
    costs = [problem.evaluate(x, problem.free, search=True)[0] for x in problem.b_held]
    assert costs == sorted(costs)
    assert any(np.array_equal(starts[1], x) for x in problem.b_held)  # the data's best grid point holds b at 0
    problem.b_held = []
    x = starts[0].copy()
    x[ib] = problem.params[ib].to_x(0.01)  # b inside its range: nothing to refit from
    before = problem.nfev
    assert velstep_missing._strengthening(problem, x) == "" and problem.nfev == before


def test_bound_meanings_name_what_each_bound_says():
    from frictionlab.inference.velstep.result import BOUND_MEANING

    assert BOUND_MEANING[("b", "lower")] == ("b at 0: the evolution runs the other way; a single-state law cannot "
                                             "follow it")
    assert {key for key, _ in BOUND_MEANING} == {"a", "b", "Dc", "k", "c"}  # c: Nagata's
    assert BOUND_MEANING[("c", "lower")].startswith("c at 0: no stress-weakening")


def test_a_multi_step_record_fits_a_b_dc_jointly_across_its_steps():
    """spring-slider-aging has two steps (1 -> 10 -> 1 um/s) in one [scene.spring]: one a, b, Dc for both, the
    generating values recovered within 3 standard errors."""
    f = fl.fit("rate-state-aging", "spring-slider-aging")
    assert len(f.velstep.rows[0].steps) == 2
    for name, true in (("a", 0.008), ("b", 0.012), ("Dc", 1e-5)):
        assert abs(f.value(name) - true) < 3 * f.stderr(name), name


def test_a_global_fit_shares_a_b_dc_and_keeps_a_stiffness_and_mu0_per_dataset(tmp_path):
    ds, curve = _measured_like(tmp_path)
    targets = []
    for i, shift in enumerate((0.0, 0.01)):
        y = curve + shift + np.random.default_rng(10 + i).normal(0.0, 4e-4, curve.size)
        d = attrs.evolve(ds, name=f"copy{i}", columns=dict(ds.columns, mu=y), noise={"mu": 4e-4})
        targets.append(Target(d, "mu", y, np.full(y.size, 4e-4)))
    f = fl.fit("rate-state-aging", targets, trend=True, stiffness=True)
    assert f.ok and {"mu0[copy0]", "mu0[copy1]", "spring.stiffness[copy0]", "spring.stiffness[copy1]"} <= set(f.params)
    assert f.value("mu0[copy1]") - f.value("mu0[copy0]") == pytest.approx(0.01, abs=5 * f.stderr("mu0[copy0]"))
    assert abs(f.value("a") - 0.009) < 3 * f.stderr("a")


def test_the_velocity_step_summary_gives_each_parameter_in_laboratory_units():
    f = fl.fit("rate-state-slip", "spring-slider-slip")
    text = f.summary()
    assert "velocity steps of spring-slider-slip" in text and " um " in text and "1/um" in text
    q = f.velstep.rows[0].quantities
    assert q["Dc"].unit == "um" and q["Dc"].value == pytest.approx(f.value("Dc") * 1e6)
    assert q["k"].unit == "1/um" and q["k"].value == pytest.approx(2000.0 * 1e-6)
    assert q["Dc"].low < q["Dc"].value < q["Dc"].high


def test_refits_of_a_velocity_step_fit_start_where_it_ended(small_step_fits):
    """The replicate refits of the equivalence test and the bootstrap go through the same path, warm-started."""
    from frictionlab.inference.resampling.replicates import refit, refit_options

    fast, _ = small_step_fits
    again = refit("rate-state-aging", refit_options(fast), fast.per_dataset[0].target)
    assert again.ok and again.velstep is None and again.stats.chisqr == pytest.approx(fast.stats.chisqr, rel=1e-6)


def test_the_compiled_sums_equal_the_explicit_projected_jacobian(tmp_path):
    """velstep_kernel.basis_sums (one pass, nothing per sample kept) against the prewhitened, projected
    residual and Jacobian formed explicitly with numpy."""
    from frictionlab.inference.noise import ar1
    from frictionlab.inference.velstep import fit as velstep
    from frictionlab.inference.velstep.kernel import basis_sums

    ds, curve = _measured_like(tmp_path, "ar1")
    y = curve + np.random.default_rng(6).normal(0.0, 4e-4, curve.size)
    data = attrs.evolve(ds, columns=dict(ds.columns, mu=y), noise={"mu": 4e-4}, noise_correlation="ar1")
    pb = velstep.make_problem(fl.get_law("rate-state-slip"), [Target(data, "mu", y, np.full(y.size, 4e-4))], {}, {},
                              {}, True, True, 1e-8)
    s = pb.series[0]
    s.set_noise(np.random.default_rng(7).normal(0.0, 1.0, y.size))  # some phi and sigma
    x = pb.x_start()
    v = pb.values(x)
    sol = quasistatic.solve(pb.code, v["a"], v["b"], v["Dc"], v["k"][0], s.load, s.t, 1e-8, sensitivities=True)
    w = ar1.whiten((s.offset(v["a"], v["b"]) + sol.m - s.y) / s.sigma, s.phi)
    J = ar1.whiten(pb.columns(s, v, x, sol.S, pb.free) / s.sigma[:, None], s.phi)
    r, Jp = w - s.Q @ (s.Q.T @ w), J - s.Q @ (s.Q.T @ J)
    cost, g, A, ok = pb.evaluate(x, pb.free)
    assert ok and cost == pytest.approx(float(r @ r), rel=1e-10)
    assert g == pytest.approx(Jp.T @ r, rel=1e-8, abs=1e-12 * np.abs(Jp.T @ r).max())
    assert A == pytest.approx(Jp.T @ Jp, rel=1e-8, abs=1e-12 * np.abs(A).max())
    ww, Bw, BB, Qw, QB = basis_sums(s.y, 0.0, sol.m, sol.S, 1 / s.sigma, np.zeros(s.n), np.ones(s.n), s.Q[:, :0])
    B = np.column_stack([sol.S, np.ones(s.n)]) / s.sigma[:, None]
    assert ww == pytest.approx(float(np.sum(((sol.m - s.y) / s.sigma) ** 2)), rel=1e-12)
    assert Bw == pytest.approx(B.T @ ((sol.m - s.y) / s.sigma), rel=1e-10, abs=1e-12 * np.abs(B.T @ B).max())
    assert BB == pytest.approx(B.T @ B, rel=1e-10) and Qw.shape == (0,) and QB.shape == (0, 5)


def test_the_equivalence_test_runs_on_ar1_velocity_steps(tmp_path):
    """Both rate-and-state laws fitted to AR(1) data; the equivalence test draws AR(1) replicates and refits both
    through the velocity-step path."""
    from frictionlab.inference.noise.ar1 import draw
    from frictionlab.io.noise import estimate

    ds, curve = _measured_like(tmp_path, "ar1")
    n = curve.size
    y = curve + draw(np.random.default_rng(1), np.full(n, 8e-4), np.r_[0.0, np.full(n - 1, 0.6)])
    cols = dict(ds.columns, mu=y)
    est = estimate(cols, "mu")
    data = attrs.evolve(ds, columns=cols, noise={"mu": est.sigma}, noise_kind="estimated", noise_est={"mu": est},
                        noise_df={"mu": est.df}, noise_correlation="ar1")
    tg = Target(data, "mu", y, np.full(n, est.sigma))
    fa, fb = fl.fit("rate-state-aging", tg), fl.fit("rate-state-slip", tg)
    e = fl.analyze_equivalence(fa, fb, replicates=20, seed=1)
    assert e.status == "ok" and 0.0 <= e.p <= 1.0 and e.failed == 0


def test_held_law_parameters_stay_held_and_the_others_are_fitted():
    """mu0 held (the model then carries mu0 + (a - b) ln(V1/V0) and its sensitivities) and Dc held: the others
    recover the generating values within 3 standard errors."""
    f = fl.fit("rate-state-aging", "spring-slider-aging", fixed={"mu0": 0.6, "Dc": 1e-5})
    assert f.params["mu0"].vary is False and f.params["Dc"].vary is False and f.value("Dc") == 1e-5
    assert f.params["mu0"].fixed_by == "held by the caller"
    for name, true in (("a", 0.008), ("b", 0.012)):
        assert abs(f.value(name) - true) < 3 * f.stderr(name), name
