"""The lean fit path gives the answers of the general one: each shortcut against the long way round."""
import math

import pytest
from _fit_helpers import TRUTH, incline_scene, synthetic

from frictionlab import fit


def test_an_ode_fit_in_a_valley_pays_for_one_start_and_says_so():
    """Couette's eta and h enter only as eta/h: the first start ends on that valley, a second would too."""
    data = synthetic("couette", TRUTH["couette"], incline_scene(), n=21, name="incline-couette")
    one = fit("couette", data, solver="ode")
    two = fit("couette", data, solver="ode", n_starts=1)  # the general path with a single start, for the count
    exact = fit("couette", data, solver="exact")
    assert one.ok and any("one Levenberg-Marquardt start of 2" in n and "correlated" in n for n in one.notes)
    assert one.nfev == two.nfev  # the second start was not run
    ratio, ref = one.params["eta/h"], exact.params["eta/h"]
    assert abs(ratio.value - ref.value) <= 0.01 * ref.stderr
    assert one.stats.chisqr == pytest.approx(exact.stats.chisqr, rel=1e-6)


def test_a_well_determined_ode_fit_still_runs_every_start():
    data = synthetic("wear", TRUTH["wear"], incline_scene(), n=21, name="incline-wear")
    r = fit("wear", data, solver="ode")
    assert r.ok and not any("Levenberg-Marquardt start" in n for n in r.notes)
    assert math.isclose(r.value("lam"), fit("wear", data, solver="exact").value("lam"), rel_tol=1e-4)


@pytest.mark.parametrize("law, params", [("coulomb", {"mu": 0.25}), ("wear", {"lam": 1e6}),
                                         ("area-rate", {"mu": 0.2, "eta_prime": 1e3}),
                                         ("couette", {"eta": 0.1, "h": 1e-7})])
def test_impact_outcomes_on_the_batch_engine_equal_the_row_by_row_solve(law, params):
    import numpy as np

    from frictionlab import get_law, load_dataset
    from frictionlab.solve.outcome import _rebounds, rows_of

    ds = load_dataset("impact-outcome-synthetic")
    rows = rows_of(ds)
    imps = [ds.scene.impact(float(a), float(b), float(c)) for a, b, c in zip(rows["speed"], rows["incidence"], rows["spin"])]
    p = get_law(law).resolve(params)
    v2, w2, rolled = _rebounds(law, imps, p, "exact", 1e-6)  # all rows in one batch
    alone = [_rebounds(law, [imp], p, "exact", 1e-6) for imp in imps]  # one row at a time: the scalar solver
    assert np.allclose(v2, [a[0][0] for a in alone], rtol=1e-12, atol=1e-12 * np.max(np.abs(v2)))
    assert np.allclose(w2, [a[1][0] for a in alone], rtol=1e-12, atol=1e-12 * np.max(np.abs(w2)))
    assert list(rolled) == [bool(a[2][0]) for a in alone]
    if law == "coulomb":
        assert 0 < rolled.sum() < len(imps)  # both kinds of row are exercised


def test_a_batch_in_chunks_equals_the_batch_in_one_call(monkeypatch):
    import numpy as np

    from frictionlab.solve import batch as B

    sb, mu, tc = _coulomb_sweep(3, 37)
    n = len(mu)
    for solver in ("exact", "DOP853"):
        whole = B.simulate_batch("coulomb", sb, {"mu": mu}, solver=solver, n=21)
        monkeypatch.setattr(B, "CHUNK", 10)
        parts = B.simulate_batch("coulomb", sb, {"mu": mu}, solver=solver, n=21)
        monkeypatch.undo()
        assert parts.info["chunks"] == 4 and whole.solver == parts.solver == solver
        for name in ("u", "v", "omega", "theta", "force", "N"):
            assert np.array_equal(getattr(whole, name), getattr(parts, name)), name
        assert np.array_equal(whole.stick_time, parts.stick_time, equal_nan=True)
        assert 0 < np.isfinite(whole.stick_time).sum() < n


@pytest.mark.parametrize("dataset", ["impact-golf-v28", "incline-dry-d10", "incline-oil-a100"])
@pytest.mark.parametrize("law", ["coulomb", "area-rate", "wear", "couette", "stribeck"])
def test_the_one_state_right_hand_side_equals_the_general_one(dataset, law):
    """Plan.derivatives on one state vector (the scalar ODE's fast path) is bitwise the batch path's."""
    import numpy as np

    from frictionlab import get_law, load_dataset
    from frictionlab.solve.plan import make_plan

    ds, lw = load_dataset(dataset), get_law(law)
    plan = make_plan(ds.scene, lw)
    p = lw.resolve({k: v for k, v in ds.fixed.items() if k in lw.param_names})
    rng = np.random.default_rng(5)
    y0 = plan.initial_state(p)
    scale = np.maximum(np.abs(y0), 1.0)
    for t in np.linspace(0.0, ds.scene.duration, 7):
        for direction in (1.0, -1.0, 0.0):
            y = y0 + scale * rng.normal(size=y0.shape)
            fast = plan.derivatives(p, t, y, direction)
            general = plan.derivatives(p, np.array([t]), y[:, None], np.array([direction]))[:, 0]
            assert np.array_equal(fast, general), (t, direction)
            assert np.array_equal(plan.bound(p, direction)(t, y), general), (t, direction)  # the ODE's bound form


def test_the_one_state_right_hand_side_reports_a_bad_force_as_the_law_does():
    import numpy as np

    from frictionlab import FrictionLaw, ParamSpec, load_dataset
    from frictionlab.core.errors import LawError
    from frictionlab.solve.plan import make_plan

    class Bad(FrictionLaw):
        name, formula, citation = "bad-rhs", "F = nan", "test"
        params = (ParamSpec("k", "", 1.0, 0.0, 2.0, 1.0, "k"),)
        requires = frozenset({"u"})

        def force(self, p, c):
            return np.full(np.shape(c.u), np.nan)

    plan = make_plan(load_dataset("incline-dry-d10").scene, Bad())
    with pytest.raises(LawError, match="NaN or infinite"):
        plan.derivatives({"k": 1.0}, 0.1, np.full(len(plan.states), 0.1), 1.0)


@pytest.mark.parametrize("method", ["LSODA", "DOP853", "RK45", "Radau", "BDF"])
@pytest.mark.parametrize("stops", [True, False])
def test_the_ode_loop_equals_solve_ivp(method, stops):
    """ode.solve is solve_ivp's loop for sorted outputs and one terminal event: the same numbers."""
    import numpy as np
    from scipy.integrate import solve_ivp

    from frictionlab.solve.solvers.ode import solve

    def f(s, z):  # a damped oscillator: z[0] crosses zero falling near s = 0.35
        return np.array([z[1], -20.0 * z[0] - 0.5 * z[1]])

    def crossing(s, z):
        return z[0] + (0.0 if stops else 5.0)

    crossing.terminal, crossing.direction = True, -1
    s_eval = np.linspace(0.0, 1.0, 41)
    ref = solve_ivp(f, (0.0, 1.0), [1.0, 0.0], method=method, t_eval=s_eval, rtol=1e-7, atol=1e-9, events=crossing)
    Z, s_event, z_event, solver = solve(f, 0.0, 1.0, [1.0, 0.0], method, s_eval, 1e-7, 1e-9, crossing, -1.0)
    assert np.array_equal(Z, ref.y) and solver.nfev == ref.nfev
    if stops:
        assert s_event == ref.t_events[0][0] and np.array_equal(z_event, ref.y_events[0][0]) and Z.shape[1] < 41
    else:
        assert s_event is None and ref.t_events[0].size == 0 and Z.shape[1] == 41


def test_the_closed_form_stop_of_coulomb_impacts_equals_the_root_finder(monkeypatch):
    """Coulomb on a half-sine pulse stops where (2/phi) arcsin(sqrt(q/2)) says: scalar and batch
    closed forms against the general bracketed root search (the fast path switched off)."""
    import numpy as np

    from frictionlab import simulate
    from frictionlab.solve import batch as B
    from frictionlab.solve.solvers import exact

    sb, mu, tc = _coulomb_sweep(11, 40)
    n = len(mu)
    t = np.linspace(0.0, 1.0, 41)[None, :] * tc[:, None]
    fast = B.simulate_batch("coulomb", sb, {"mu": mu}, solver="exact", t=t)
    scalar_fast = [simulate("coulomb", sb.scene(i), {"mu": mu[i]}, solver="exact", t=t[i]) for i in range(n)]
    monkeypatch.setattr(exact, "closed_stop_applies", lambda plan, form, t0: False)
    slow = B.simulate_batch("coulomb", sb, {"mu": mu}, solver="exact", t=t)
    scalar_slow = [simulate("coulomb", sb.scene(i), {"mu": mu[i]}, solver="exact", t=t[i]) for i in range(n)]
    stops = np.isfinite(slow.stick_time)
    assert 0 < stops.sum() < n and np.array_equal(stops, np.isfinite(fast.stick_time))
    assert np.allclose(fast.stick_time[stops], slow.stick_time[stops], rtol=0, atol=1e-12 * tc.max())
    for name in ("u", "v", "omega", "theta"):
        a, b = getattr(fast, name), getattr(slow, name)
        assert np.allclose(a, b, rtol=1e-10, atol=1e-10 * np.max(np.abs(b))), name
    for f, s_ in zip(scalar_fast, scalar_slow):
        assert (f.stick_time is None) == (s_.stick_time is None)
        if f.stick_time is not None:
            assert abs(f.stick_time - s_.stick_time) <= 1e-12 * tc.max()
        assert np.allclose(f.omega, s_.omega, rtol=1e-10, atol=1e-10 * np.max(np.abs(s_.omega)))


def _coulomb_sweep(seed: int, n: int):
    """n random golf-ball impacts with Coulomb friction and rolling: (SceneBatch, mu, contact times [s])."""
    import numpy as np

    from frictionlab.physics.scene import HalfSineNormal, Scene
    from frictionlab.solve import batch as B

    rng = np.random.default_rng(seed)
    tc = rng.uniform(400e-6, 500e-6, n)
    template = Scene(kind="impact", mass=0.046, u0=1.0, duration=tc[0], radius=0.0213,
                     normal=HalfSineNormal(1.0, tc[0]), effects=frozenset({"slip-coupling", "spin"}))
    sb = B.SceneBatch.sweep(template, {"u0": rng.uniform(2, 40, n), "normal.impulse": rng.uniform(0.5, 4, n),
                                       "normal.contact_time": tc, "duration": tc})
    return sb, rng.uniform(0.1, 0.5, n), tc


def test_a_fit_without_checks_reaches_the_full_fits_minimum():
    """fit(checks=False), the replicate refits' path, skips the plausibility flags and lmfit's SI copy, and refits
    through scipy's least_squares (``lsrefit``): chi-square within 1e-9 of the full fit's, values within 1e-3 of
    their error bars, error bars within 1e-3 of lmfit's."""
    data = synthetic("area-rate", TRUTH["area-rate"], incline_scene(), n=21, name="incline-area-rate")
    full, lean = fit("area-rate", data, solver="exact"), fit("area-rate", data, solver="exact", checks=False)
    assert full.ok and lean.ok and full.minimizer_result is not None and lean.minimizer_result is None
    assert full.plausibility and not lean.plausibility and lean.flags == ()
    assert lean.stats.chisqr == pytest.approx(full.stats.chisqr, rel=1e-9)
    assert (lean.stats.n_points, lean.stats.n_params) == (full.stats.n_points, full.stats.n_params)
    assert any(p.stderr for p in full.params.values())
    for k, p in full.params.items():
        if p.stderr is None:  # held
            assert (lean.params[k].value, lean.params[k].stderr) == (p.value, None), k
            continue
        assert abs(lean.params[k].value - p.value) <= 1e-3 * p.stderr, k
        assert lean.params[k].stderr == pytest.approx(p.stderr, rel=1e-3), k


def test_impact_outcome_rows_are_built_once_per_scene_and_rows_with_the_same_answers():
    """predict_outcomes keeps the last rows' impacts (and their batch) for the same scene object: a second call
    reuses them and gives the same outcomes as a fresh build; another scene object (a freed quantity) is its own."""
    import attrs
    import numpy as np

    from frictionlab import load_dataset
    from frictionlab.solve import outcome

    ds = load_dataset("impact-outcome-synthetic")
    rows = outcome.rows_of(ds)
    outcome._INBOUND.clear()
    outcome._BATCHES.clear()
    first = outcome.predict_outcomes("area-rate", ds.scene, {"mu": 0.2, "eta_prime": 400.0}, "exact", **rows)
    imps = outcome._inbound(ds.scene, rows)
    again = outcome.predict_outcomes("area-rate", ds.scene, {"mu": 0.2, "eta_prime": 400.0}, "exact", **rows)
    assert outcome._inbound(ds.scene, rows) is imps and len(outcome._BATCHES) == 1
    heavier = attrs.evolve(ds.scene, mass=2 * ds.scene.mass)
    assert outcome._inbound(heavier, rows) is not imps
    outcome._INBOUND.clear()
    outcome._BATCHES.clear()
    fresh = outcome.predict_outcomes("area-rate", ds.scene, {"mu": 0.2, "eta_prime": 400.0}, "exact", **rows)
    for k in ("rebound_spin", "tangential_cor", "rebound_angle", "rolled"):
        assert np.array_equal(first[k], again[k]) and np.array_equal(first[k], fresh[k]), k
    assert not np.array_equal(outcome.predict_outcomes("area-rate", heavier, {"mu": 0.2, "eta_prime": 400.0}, "exact",
                                                       **rows)["rebound_spin"], first["rebound_spin"])


def test_a_fit_without_error_analysis_gives_the_same_values_and_chi_square():
    """fit(errors=False), the equivalence test's replicate refits: no Jacobian (2 evaluations per free
    parameter fewer), the same search, values and chi-square; every free parameter counted in k."""
    data = synthetic("couette", TRUTH["couette"], incline_scene(), n=21, name="incline-couette")
    full, lean = fit("couette", data, solver="exact"), fit("couette", data, solver="exact", errors=False)
    assert full.ok and lean.ok and lean.stats.chisqr == full.stats.chisqr
    assert lean.nfev == full.nfev - 2 * 2  # eta and h: a central difference each
    assert {k: p.value for k, p in lean.params.items() if p.kind != "derived"} == \
        {k: p.value for k, p in full.params.items() if p.kind != "derived"}
    assert full.stats.n_params == 1 and lean.stats.n_params == 2  # eta/h only: the structure is not looked for


@pytest.mark.parametrize("law, solver", [("wear", "exact"), ("area-rate", "exact"), ("wear", "ode")])
def test_the_best_fit_model_taken_from_the_last_evaluation_equals_a_fresh_prediction(law, solver):
    """fit() reuses lmfit's last evaluation (at its best values) for the best-fit model: the same numbers as a
    prediction made afresh at the fitted parameters; and a fit with several starts gives the same answer."""
    import numpy as np

    from frictionlab.inference.fitting.predict import predict

    data = synthetic(law, TRUTH[law], n=21, name=f"reuse-{law}")
    r = fit(law, data, solver=solver)
    assert r.ok
    d = r.per_dataset[0]
    fresh = predict(law, d.target, d.params, d.solver, d.scene, None)
    assert np.array_equal(d.model, fresh)
    assert d.chisqr == float(np.sum(((fresh - d.target.y) / d.target.sigma) ** 2))


@pytest.mark.parametrize("law, solver, options", [("area-rate", "exact", {}), ("wear", "exact", {"scan": 0}),
                                                  ("couette", "ode", {})])
def test_a_repeated_evaluation_reused_gives_the_fit_of_the_general_path(law, solver, options, monkeypatch):
    """The residual at the values of the last evaluation (scipy's leastsq asks for its start twice) and the
    best-fit model are reused: the same fit, number for number, as when every call evaluates afresh."""
    import numpy as np

    from frictionlab.inference.fitting import fit as fitting

    data = synthetic(law, TRUTH[law], n=21, name=f"reuse2-{law}")
    fast = fit(law, data, solver=solver, **options)
    fresh = fitting._Model.residual

    def always_fresh(self, values, given=None):
        self._last = None
        return fresh(self, values, given)

    monkeypatch.setattr(fitting._Model, "residual", always_fresh)
    slow = fit(law, data, solver=solver, **options)
    assert fast.ok and slow.ok
    assert {k: p.value for k, p in fast.params.items()} == {k: p.value for k, p in slow.params.items()}
    assert {k: p.stderr for k, p in fast.params.items()} == {k: p.stderr for k, p in slow.params.items()}
    assert fast.stats.chisqr == slow.stats.chisqr and np.array_equal(fast.per_dataset[0].model, slow.per_dataset[0].model)
    assert fast.nfev < slow.nfev  # evaluations saved, counted as such


def _numbers(r):
    return (r.status, r.message, r.nfev, r.stats.chisqr, r.stats.aic, sorted(r.correlations.items()),
            {k: (p.value, p.stderr) for k, p in r.params.items()})


def test_the_scalar_right_hand_side_takes_a_constant_normal_force_built_once():
    """An incline's weight (a normal force that does not change in time) is built once per bound right-hand side,
    read-only, equal to the scene's at any time; a normal force that changes (an impact's) is not."""
    import numpy as np

    from frictionlab import get_law, load_dataset
    from frictionlab.solve.plan import make_plan

    incline = make_plan(load_dataset("incline-dry-d10").scene, get_law("area-rate"))
    N = incline._fixed_normal()
    assert N is not None and not N.flags.writeable and np.array_equal(N, incline.scene.normal(0.37))
    assert make_plan(load_dataset("impact-golf-v28").scene, get_law("area-rate"))._fixed_normal() is None
    assert make_plan(load_dataset("incline-dry-d10").scene, get_law("wear"))._fixed_normal() is None  # not needed


def test_the_impulse_alone_is_the_impulse_of_both_integrals():
    """The exact solver's stop search reads the friction impulse only (``second=False``): bit for bit the
    impulse computed beside its integral, for half-sine and constant pulses, small and large (in-place)
    grids, times past contact, and a factor per scene."""
    import numpy as np

    from frictionlab.physics.area import ConstantArea, HalfSineArea
    from frictionlab.physics.normal import HalfSineNormal, WeightNormal
    from frictionlab.solve.solvers.exact import _area_integrals, _normal_integrals

    rng = np.random.default_rng(5)
    grids = [np.float64(1.7e-4), rng.uniform(0, 6e-4, 7), np.sort(rng.uniform(0, 4e-4, (3, 40)), axis=1)]
    for normal in (HalfSineNormal(impulse=1.3, contact_time=5e-4), WeightNormal(value=2.5)):
        for t in grids:
            for a in (0.31, rng.uniform(0.1, 1.0, (3, 1)) if np.ndim(t) == 2 else 0.7):
                both, alone = _normal_integrals(normal, t, a), _normal_integrals(normal, t, a, second=False)
                assert alone[1] is None and np.array_equal(alone[0], both[0])
    for area in (HalfSineArea(peak=1.3e-4, contact_time=5e-4), ConstantArea(area=2e-5), None):
        for t in grids[1:]:
            alone = _area_integrals(area, t, second=False)
            assert alone[1] is None and np.array_equal(alone[0], _area_integrals(area, t)[0])


def test_refits_of_resampled_data_share_the_evaluations_the_data_do_not_change(monkeypatch):
    """A model never reads the data it is fitted to: refits warm-started at one fit's values (replicates) share
    their first evaluations (the start, its finite-difference steps), computed once; the numbers are those of
    refits that compute every evaluation. A copy with other times, or a kind a third party predicts, shares none."""
    import attrs
    import numpy as np

    from frictionlab import get_law
    from frictionlab.inference.fitting import batch as batchfit
    from frictionlab.inference.fitting import model as fitmodel
    from frictionlab.inference.fitting import predict as predict_module
    from frictionlab.inference.resampling.replicates import refit, refit_options, with_y

    monkeypatch.setattr(batchfit, "best_start", lambda *a: None)  # the one-at-a-time path (an ODE's, a plugin's)

    data = synthetic("area-rate", TRUTH["area-rate"], n=21, name="shared-evals", rel_noise=0.03)
    base = fit("area-rate", data, solver="exact")
    opts, tg, model = refit_options(base), base.per_dataset[0].target, base.per_dataset[0].model
    rng = np.random.default_rng(1)
    replicates = [with_y(tg, model + rng.standard_normal(tg.y.size) * tg.sigma, "replicate") for _ in range(3)]
    computed = [0]
    real = fitmodel.predict

    def counted(*a, **k):
        computed[0] += 1
        return real(*a, **k)

    monkeypatch.setattr(fitmodel, "predict", counted)
    fitmodel._SHARED.clear()
    shared, counts = [], []
    for r in replicates:
        before = computed[0]
        shared.append(refit("area-rate", opts, r))
        counts.append(computed[0] - before)
    monkeypatch.setattr(fitmodel, "design", lambda target: None)  # every evaluation computed afresh
    fresh = [refit("area-rate", opts, r) for r in replicates]
    for a, b in zip(shared, fresh):
        assert a.nfev == b.nfev and a.stats.chisqr == b.stats.chisqr
        assert {k: p.value for k, p in a.params.items()} == {k: p.value for k, p in b.params.items()}
    assert len(counts) == 3 and counts[1] <= counts[0] - 3 and counts[2] <= counts[0] - 3  # start and two steps
    assert all(r.per_dataset[0].model.flags.writeable for r in shared)  # a result's model is its own array

    monkeypatch.setattr(fitmodel, "design", predict_module.design)
    later = with_y(tg, tg.y, "times moved")
    later = attrs.evolve(later, dataset=attrs.evolve(tg.dataset, columns={**tg.dataset.columns,
                                                                          "t": tg.dataset.columns["t"] * 0.9}))
    p = {k: v.value for k, v in base.params.items()}
    law = get_law("area-rate")
    got = fitmodel._shared_predict(law, later, p, "exact", later.dataset.scene, None)
    assert np.array_equal(got, real(law, later, p, "exact", later.dataset.scene, None))
    assert not np.array_equal(got, fitmodel._shared_predict(law, tg, p, "exact", tg.dataset.scene, None))
    assert not got.flags.writeable
    monkeypatch.setitem(predict_module.PREDICTORS, tg.dataset.kind, lambda *a, **k: model)
    assert predict_module.design(tg) is None


@pytest.mark.parametrize("dataset", ["kharaz2001-spin", "impact-outcome-synthetic"])
def test_the_start_scan_of_impact_outcomes_in_one_batch_gives_the_fit_of_the_scan_one_by_one(dataset, monkeypatch):
    """A start scan of an impact-outcome fit predicts every grid point's rows in one call of the batch engine:
    each prediction bitwise that of ``predict`` alone, and the fit number for number the one-by-one scan's."""
    import numpy as np

    from frictionlab.inference.fitting import model as fitmodel
    from frictionlab.inference.fitting.predict import make_target, predict, predict_many

    tg = make_target(dataset)
    sets = [{"mu": mu, "eta_prime": eta} for mu in (0.05, 0.3, 2.0) for eta in (-3e4, 0.0, 5e2)]
    many = predict_many("area-rate", tg, sets, "exact")
    assert many is not None and len(many) == len(sets)
    for p, m in zip(sets, many):
        assert np.array_equal(m, predict("area-rate", tg, p, "exact"))
    assert predict_many("area-rate", tg, sets, "ode") is None  # no batch of the ODE path: one by one
    batched = fit("area-rate", dataset, solver="exact", scan=25, n_starts=2)
    monkeypatch.setattr(fitmodel, "predict_many", lambda *a, **k: None)
    alone = fit("area-rate", dataset, solver="exact", scan=25, n_starts=2)
    assert batched.ok and alone.ok and batched.nfev == alone.nfev
    assert _numbers(batched) == _numbers(alone)


def _area_rate_sweep(seed: int, n: int):
    """n random impacts with half-sine N and A of one contact time, slip coupling, and area-rate parameters of both
    signs of eta' (stops early, late or never): (SceneBatch, params, contact times [s])."""
    import numpy as np

    from frictionlab.physics.scene import HalfSineArea, HalfSineNormal, Scene
    from frictionlab.solve import batch as B

    rng = np.random.default_rng(seed)
    tc = rng.uniform(400e-6, 500e-6, n)
    template = Scene(kind="impact", mass=0.046, u0=1.0, duration=tc[0], radius=0.0213,
                     normal=HalfSineNormal(1.0, tc[0]), area=HalfSineArea(1e-4, tc[0]),
                     effects=frozenset({"slip-coupling", "spin"}))
    sb = B.SceneBatch.sweep(template, {"u0": rng.uniform(2, 40, n), "normal.impulse": rng.uniform(0.5, 4, n),
                                       "area.peak": rng.uniform(2e-5, 2e-4, n), "normal.contact_time": tc,
                                       "area.contact_time": tc, "duration": tc})
    params = {"mu": rng.uniform(0.05, 0.6, n), "eta_prime": rng.choice([-1, 1], n) * 10 ** rng.uniform(0, 4, n)}
    return sb, params, tc


def test_the_closed_form_stop_of_area_rate_impacts_equals_the_scan_and_root_finder(monkeypatch):
    """Area-rate on half-sine N and A slips as C0 + R cos(phi t - delta): its first stop in closed form
    (exact.pulse_stop), scalar and batch, against the scan and bracketed root search (closed form switched off)."""
    import numpy as np

    from frictionlab import simulate
    from frictionlab.solve import batch as B
    from frictionlab.solve.solvers import exact

    sb, params, tc = _area_rate_sweep(5, 60)
    n = len(tc)
    t = np.linspace(0.0, 1.0, 41)[None, :] * tc[:, None]
    one = [{k: float(v[i]) for k, v in params.items()} for i in range(n)]
    fast = B.simulate_batch("area-rate", sb, params, solver="exact", t=t)
    scalar_fast = [simulate("area-rate", sb.scene(i), one[i], solver="exact", t=t[i]) for i in range(n)]
    monkeypatch.setattr(exact, "_pulse_slip", lambda *a: None)
    slow = B.simulate_batch("area-rate", sb, params, solver="exact", t=t)
    scalar_slow = [simulate("area-rate", sb.scene(i), one[i], solver="exact", t=t[i]) for i in range(n)]
    stops = np.isfinite(slow.stick_time)
    assert 10 < stops.sum() < n - 10 and np.array_equal(stops, np.isfinite(fast.stick_time))
    assert np.allclose(fast.stick_time[stops], slow.stick_time[stops], rtol=0, atol=1e-12 * tc.max())
    for f, s_ in zip(scalar_fast, scalar_slow):
        assert (f.stick_time is None) == (s_.stick_time is None)
        if f.stick_time is not None:
            assert abs(f.stick_time - s_.stick_time) <= 1e-12 * tc.max()
        assert np.allclose(f.omega, s_.omega, rtol=1e-10, atol=1e-10 * np.max(np.abs(s_.omega)))


def test_the_closed_form_stop_of_a_block_on_an_incline_equals_the_scan_and_root_finder(monkeypatch):
    """On an incline (weight normal force, no area term) slip is linear in time: its stop in closed form against
    the scan and bracketed root search, for blocks thrown up and down the slope, sliding on or stopping."""
    import attrs
    import numpy as np

    from frictionlab import simulate
    from frictionlab.solve.solvers import exact

    rng = np.random.default_rng(3)
    base = incline_scene()
    cases = [(attrs.evolve(base, u0=float(rng.uniform(-3, 3))), law,
              {"mu": float(10 ** rng.uniform(-1.5, 0.3))} | ({"eta_prime": 10.0} if law == "area-rate" else {}))
             for law in ("coulomb", "area-rate") for _ in range(40)]
    fast = [simulate(law, s, p, solver="exact") for s, law, p in cases]
    monkeypatch.setattr(exact, "_linear_slip", lambda *a: None)
    slow = [simulate(law, s, p, solver="exact") for s, law, p in cases]
    stopped = sum(s_.stick_time is not None for s_ in slow)
    assert 10 < stopped < len(cases) - 10
    for f, s_, (scene, _, _) in zip(fast, slow, cases):
        assert (f.stick_time is None) == (s_.stick_time is None)
        if f.stick_time is not None:
            assert abs(f.stick_time - s_.stick_time) <= 1e-12 * scene.duration
        assert np.allclose(f.v, s_.v, rtol=1e-12, atol=1e-12 * np.max(np.abs(s_.v)))
