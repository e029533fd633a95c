"""The batched refits (inference.fitting.batch) against the one-at-a-time refits they stand in for."""
import math

import numpy as np
import pytest
from _fit_helpers import TRUTH, impact_scene, incline_scene, synthetic

from frictionlab import fit
from frictionlab.inference.fitting import batch as batchfit
from frictionlab.inference.resampling import bootstrap
from frictionlab.inference.fitting.predict import predict, predict_array
from frictionlab.inference.resampling import replicates
from frictionlab.inference.resampling.replicates import (batch_problem, refit, refit_options, replicate_chunk, seed_sequence,
                                               with_y)

CASES = [("coulomb", "exact", "impact"), ("wear", "exact", "impact"), ("wear", "series", "impact"),
         ("area-rate", "exact", "impact"), ("couette", "exact", "impact"), ("coulomb", "exact", "incline"),
         ("area-rate", "exact", "incline"), ("wear", "exact", "incline")]


def _data(truth: str, where: str):
    scene = impact_scene() if where == "impact" else incline_scene()
    return synthetic(truth, TRUTH[truth], scene, n=26 if where == "impact" else 41, name=f"{where}-{truth}")


def _one_at_a_time(monkeypatch):
    """Every refit one at a time (lsrefit: Levenberg-Marquardt through scipy's least_squares), no batch anywhere."""
    monkeypatch.setattr(replicates, "batch_problem", lambda *a, **k: None)
    monkeypatch.setattr(batchfit, "best_start", lambda *a, **k: None)


def _replicates(f, n: int, seed: int = 3):
    tg = f.per_dataset[0].target
    return tg, f.per_dataset[0].model + np.random.default_rng(seed).normal(0.0, tg.sigma, (n, tg.y.size))


def _batched_reaches_the_single_minimum(f, n: int, monkeypatch):
    """n replicates of fit ``f``'s curve, refitted in one batch: every row converges to the one-at-a-time refit's
    chi-square (within its tolerance) or lower, its values within 0.01 SE of that refit's where the minimum is
    the same."""
    law, tg, opts = f.law, f.per_dataset[0].target, refit_options(f)
    _, Y = _replicates(f, n)
    many = batchfit.refit_many(batch_problem(law, opts, tg), Y)
    assert many is not None and many.ok.all()
    _one_at_a_time(monkeypatch)
    for i in range(n):
        one = refit(law, opts, with_y(tg, Y[i], "replicate"))
        assert one.ok
        assert many.chisqr[i] <= one.stats.chisqr * (1 + 1e-6) + 1e-9
        if many.chisqr[i] >= one.stats.chisqr * (1 - 1e-6):
            for k in opts["initial"]:
                se = f.params[k].stderr or abs(f.params[k].value)
                assert abs(many.values[k][i] - one.params[k].value) <= 0.01 * se, k


@pytest.mark.parametrize("law, solver, where", CASES)
def test_the_batched_prediction_is_the_single_one_to_round_off(law, solver, where):
    f = fit(law, _data(law, where), solver=solver)
    tg = f.per_dataset[0].target
    rng = np.random.default_rng(0)
    sets = [{k: p.value * float(rng.uniform(0.5, 1.5)) for k, p in f.params.items() if p.kind == "law"}
            for _ in range(7)]
    got = predict_array(law, tg, {k: np.array([s[k] for s in sets]) for k in sets[0]}, solver)
    want = np.array([predict(law, tg, s, solver) for s in sets])
    assert got.shape == want.shape
    assert np.max(np.abs(got - want)) <= 1e-12 * np.max(np.abs(want))


@pytest.mark.parametrize("law, solver, where", CASES)
@pytest.mark.parametrize("truth", ["coulomb", "area-rate"])
def test_batched_refits_reach_the_single_refits_minimum(law, solver, where, truth, monkeypatch):
    """Every row converges; its chi-square is the single refit's within that refit's own tolerance (relative
    1e-6), or lower; its values within 0.01 of the base fit's standard error where it is not lower."""
    f = fit(law, _data(truth, where), solver=solver)
    assert f.ok
    opts = refit_options(f)
    tg, Y = _replicates(f, 12)
    got = batchfit.refit_many(batch_problem(law, opts, tg), Y)
    assert got is not None and got.ok.all()
    via_fit = [refit(law, opts, with_y(tg, Y[i], "replicate")) for i in range(len(Y))]  # the batched starts' answer
    assert np.allclose([r.stats.chisqr for r in via_fit], got.chisqr, rtol=1e-9)
    _one_at_a_time(monkeypatch)
    for i in range(len(Y)):
        one = refit(law, opts, with_y(tg, Y[i], "replicate"))
        assert one.ok
        assert got.chisqr[i] <= one.stats.chisqr * (1 + 1e-6) + 1e-9
        assert np.allclose(got.models[i], predict(law, tg, got.row(i), solver), rtol=1e-12, atol=0)
        if got.chisqr[i] >= one.stats.chisqr * (1 - 1e-6):  # the same minimum: the same values
            for k in opts["initial"]:
                se = f.params[k].stderr or abs(f.params[k].value)
                assert abs(got.values[k][i] - one.params[k].value) <= 0.01 * se, k


def test_rows_start_where_they_are_told():
    f = fit("coulomb", _data("coulomb", "impact"), solver="exact")
    opts, (tg, Y) = refit_options(f), _replicates(f, 3)
    far = {"mu": np.full(3, 3.0 * f.value("mu"))}
    pr = batch_problem("coulomb", opts, tg)
    near = batchfit.refit_many(pr, Y)
    from_far = batchfit.refit_many(pr, Y, starts=far)
    assert np.allclose(from_far.chisqr, near.chisqr, rtol=1e-8)
    assert (batchfit.refit_many(pr, Y, starts={"mu": np.full(3, f.value("mu"))}).chisqr
            == near.chisqr).all()


def test_no_batched_route_where_the_single_refit_must_serve():
    data = _data("wear", "impact")
    f = fit("wear", data, solver="exact")
    tg = f.per_dataset[0].target
    opts = refit_options(f)
    assert batch_problem("wear", opts, tg) is not None
    assert batch_problem("wear", opts | {"solver": "ode"}, tg) is None  # an ODE solve is not batched
    assert batch_problem("wear", opts | {"free": {"u0": (10.0, 14.0, 12.0)}}, tg) is None  # a freed scene value
    import frictionlab as fl

    cls = type("MyWear", (fl.FrictionLaw,), {  # a third-party law: its refits keep their time budget, one at a time
        "name": "my-wear-batchfit", "formula": "F = c u", "citation": "test",
        "params": (fl.ParamSpec("c", "N s/m", 1.0, 0.0, 10.0, 1.0, "coefficient"),),
        "requires": frozenset({"u"}), "force": lambda self, p, c: p["c"] * c.u})
    fl.register_law(cls)
    try:
        assert batch_problem("my-wear-batchfit", {"solver": "exact", "initial": {"c": 1.0}, "fixed": {}}, tg) is None
    finally:
        fl.unregister_law("my-wear-batchfit")


def test_the_equivalence_replicates_are_those_of_the_single_refits(monkeypatch):
    data = _data("area-rate", "impact")
    fa, fb = fit("wear", data, solver="exact"), fit("area-rate", data, solver="exact")
    args = ("wear", refit_options(fa), "area-rate", refit_options(fb), fa.per_dataset[0].target,
            fa.per_dataset[0].model, fb.per_dataset[0].model, seed_sequence(0, "test").spawn(6))
    batched = np.array(replicate_chunk(*args))
    _one_at_a_time(monkeypatch)
    single = np.array(replicate_chunk(*args))
    assert batched.shape == single.shape == (6, 7)
    scale = max(1.0, float(np.max(np.abs(single[:, [0, 1, 3, 4]]))))
    assert np.max(np.abs(batched - single)) <= 1e-5 * scale  # chi-square differences: within the refits' tolerance


def test_the_bootstrap_replicates_are_those_of_the_single_refits(monkeypatch):
    data = _data("coulomb", "impact")
    boot = lambda: bootstrap.bootstrap(bootstrap.law_fit("area-rate", "exact"), data, n=24, seed=5,  # noqa: E731
                                       method="parametric")
    batched = boot()
    _one_at_a_time(monkeypatch)
    single = boot()
    assert batched.n_ok == single.n_ok == 24
    for name in batched.names:
        se = batched.base.params[name].stderr
        assert np.max(np.abs(batched.samples - single.samples)[:, batched.names.index(name)]) <= 0.01 * se
    assert np.allclose(batched.aic, single.aic, rtol=0, atol=1e-4)
    assert math.isclose(batched.std("mu"), single.std("mu"), rel_tol=1e-3)


@pytest.mark.parametrize("law, solver", [("coulomb", "exact"), ("area-rate", "exact"), ("wear", "exact"),
                                         ("wear", "series"), ("couette", "exact")])
def test_stated_numbers_are_read_off_a_batch_as_off_one_trajectory(law, solver, monkeypatch):
    """A reconstruction's stated numbers (peak spin and its time, end spin, largest angle): the batched
    prediction equals the single one, and the batched refits of replicates of them reach the single refits'
    minimum (values within 0.01 SE where the minimum is the same)."""
    f = fit(law, "impact-golf-v28", solver=solver)
    tg = f.per_dataset[0].target
    assert tg.observable == "stated" and f.ok
    rng = np.random.default_rng(1)
    sets = [{k: p.value * float(rng.uniform(0.6, 1.4)) for k, p in f.params.items() if p.kind == "law"}
            for _ in range(6)]
    got = predict_array(law, tg, sets, solver)
    want = np.array([predict(law, tg, s, solver) for s in sets])
    assert got.shape == want.shape == (6, 4)
    assert np.max(np.abs(got - want) / np.abs(want)) <= 1e-12
    _batched_reaches_the_single_minimum(f, 8, monkeypatch)


@pytest.mark.parametrize("law, dataset", [("coulomb", "impact-outcome-synthetic"), ("area-rate", "kharaz2001-spin"),
                                          ("wear", "impact-outcome-synthetic")])
def test_impact_outcomes_are_predicted_and_refitted_in_batches(law, dataset, monkeypatch):
    """Every parameter set's impacts in one batch of closed forms: the batched prediction equals the one-at-a-time
    one, and the batched refits of replicates reach the single refits' minimum (values within 0.01 SE where it is
    the same minimum)."""
    f = fit(law, dataset, solver="exact")
    tg = f.per_dataset[0].target
    assert tg.dataset.kind == "impact-outcome" and f.ok
    rng = np.random.default_rng(2)
    sets = [{k: p.value * float(rng.uniform(0.7, 1.3)) for k, p in f.params.items() if p.kind == "law"}
            for _ in range(5)]
    got = predict_array(law, tg, sets, "exact")
    want = np.array([predict(law, tg, s, "exact") for s in sets])
    assert got.shape == want.shape == (5, tg.y.size)
    assert np.max(np.abs(got - want)) <= 1e-12 * np.max(np.abs(want))
    assert predict_array(law, tg, sets, "ode") is None  # only the closed forms are batched
    _batched_reaches_the_single_minimum(f, 6, monkeypatch)
