"""fit(): parameter recovery, scaling, fixed and free quantities, global fits, identifiability, failures."""
import math

import numpy as np
import pytest
from _fit_helpers import TRUTH, impact_scene, incline_scene, synthetic

from frictionlab import FrictionLabError, FrictionLaw, ParamSpec, fit, make_target
from frictionlab.core.errors import DatasetError, ParameterError
from frictionlab.solve.choice import applicable_solvers, auto_solver
from frictionlab.physics.derive import derive_omega
from frictionlab.physics.law import AreaSlipForm


def within(p, truth, n_sigma=3.0):
    assert p.stderr is not None and p.stderr > 0
    return abs(p.value - truth) <= n_sigma * p.stderr


def test_wear_recovers_lambda_at_its_real_scale():
    ds = synthetic("wear", {"lam": 1.2e6})
    r = fit("wear", ds, solver="exact")
    assert r.ok, r.reason
    lam = r.params["lam"]
    assert within(lam, 1.2e6)
    assert lam.stderr < 0.02 * lam.value  # 1% noise on 26 points pins lambda to about 0.5%
    assert r.identifiability.verdict == "identifiable"
    assert r.stats.n_points == 26 and r.stats.n_params == 1
    assert 0.3 < r.stats.redchi < 3.0  # noise weights are the generating noise


def test_start_far_from_truth_is_found_by_the_grid():
    ds = synthetic("wear", {"lam": 1.2e6})
    r = fit("wear", ds, solver="exact", initial={"lam": 2e4})
    assert r.ok and within(r.params["lam"], 1.2e6)


def test_dataset_fixed_value_is_held_and_the_partner_recovered():
    ds = synthetic("couette", TRUTH["couette"], fixed={"eta": 0.1})
    r = fit("couette", ds, solver="exact")
    assert r.ok
    assert not r.params["eta"].vary and r.params["eta"].value == 0.1 and "[fixed]" in r.params["eta"].fixed_by
    assert within(r.params["h"], TRUTH["couette"]["h"])  # h ~ 1e-7 m: scaling must cope
    assert not r.identifiability.ratio_only


def test_ratio_only_pair_is_reported_and_counted_once():
    ds = synthetic("couette", TRUTH["couette"])
    r = fit("couette", ds, solver="exact")
    w = fit("wear", ds, solver="exact")
    assert r.ok and w.ok
    assert r.identifiability.ratio_only == (("eta", "h"),)
    assert r.params["eta"].stderr is None and r.params["h"].stderr is None
    ratio = r.params["eta/h"]
    assert ratio.kind == "derived"
    assert ratio.value == pytest.approx(w.value("lam"), rel=1e-4)
    assert ratio.stderr == pytest.approx(w.stderr("lam"), rel=0.05)
    assert r.stats.n_params == 1 == w.stats.n_params
    assert r.stats.aic == pytest.approx(w.stats.aic, abs=1e-3)


def test_parameter_without_effect_is_flagged_and_others_keep_errors():
    ds = synthetic("coulomb", {"mu": 0.25}, incline_scene(), n=40)
    r = fit("area-rate", ds, solver="exact")
    assert r.ok
    assert r.identifiability.no_effect == ("eta_prime",)
    assert r.params["eta_prime"].stderr is None
    assert within(r.params["mu"], 0.25)
    assert r.stats.n_params == 1


def test_free_scene_quantity_is_recovered():
    truth = impact_scene(u0=10.0)
    ds = synthetic("wear", {"lam": 1.2e6}, impact_scene(u0=12.0), truth_scene=truth)
    r = fit("wear", ds, solver="exact", free={"u0": (5.0, 14.0)})
    assert r.ok
    assert within(r.params["u0"], 10.0) and within(r.params["lam"], 1.2e6)
    assert r.params["u0"].kind == "scene" and r.params["u0"].unit == "m/s"
    stuck = fit("wear", ds, solver="exact")  # holding the wrong u0 is clearly worse, even after the AIC penalty
    assert stuck.stats.aic - r.stats.aic > 10


def test_global_fit_shares_law_parameters_and_frees_scene_per_dataset():
    a = synthetic("wear", {"lam": 1.2e6}, impact_scene(u0=12.0), name="a", seed=1)
    b = synthetic("wear", {"lam": 1.2e6}, impact_scene(u0=8.0), name="b", seed=2, truth_scene=impact_scene(u0=9.0))
    r = fit("wear", [a, b], solver="exact", free={"u0": (5.0, 14.0)})
    assert r.ok and r.datasets == ("a", "b")
    assert set(r.params) == {"lam", "u0[a]", "u0[b]"}
    assert within(r.params["lam"], 1.2e6) and within(r.params["u0[b]"], 9.0)
    assert r.stats.n_points == 52 and math.isnan(r.stats.rss)
    local = fit("wear", [a, b], solver="exact", local=["lam"])
    assert set(local.params) == {"lam[a]", "lam[b]"}


def test_residuals_are_noise_weighted_so_units_do_not_matter():
    ds = synthetic("wear", {"lam": 1.2e6})
    r1 = fit("wear", ds, solver="exact")
    scaled = synthetic("wear", {"lam": 1.2e6})
    tg = make_target(scaled)
    tg2 = type(tg)(tg.dataset, tg.observable, tg.y, tg.sigma * 10)
    r2 = fit("wear", tg2, solver="exact")
    assert r2.value("lam") == pytest.approx(r1.value("lam"), rel=1e-6)
    assert r2.stats.chisqr == pytest.approx(r1.stats.chisqr / 100, rel=1e-6)


def test_fit_to_theta_directly():
    ds = synthetic("wear", {"lam": 1.2e6}, rel_noise=0.005)
    r = fit("wear", ds, solver="exact", observable="theta")
    assert r.ok and r.per_dataset[0].target.observable == "theta"
    assert within(r.params["lam"], 1.2e6)


@pytest.mark.parametrize("route", ["poly9", "spline"])
def test_fit_to_omega_derived_from_theta(route):
    ds = synthetic("wear", {"lam": 1.2e6}, rel_noise=0.002, n=51)
    r = fit("wear", ds, solver="exact", derive=route)
    assert r.ok and route in r.per_dataset[0].target.derivation
    assert r.value("lam") == pytest.approx(1.2e6, rel=0.05)


def test_poly9_derivative_is_exact_on_a_polynomial_and_propagates_noise():
    t = np.linspace(0, 5e-4, 40)
    theta = 3.0 * (t / 5e-4) ** 3 - (t / 5e-4) ** 7
    d = derive_omega(t, theta, "poly9", sigma_theta=0.01)
    exact = (9.0 * (t / 5e-4) ** 2 - 7 * (t / 5e-4) ** 6) / 5e-4
    assert np.allclose(d.omega, exact, rtol=1e-6, atol=1e-6 * np.max(np.abs(exact)))
    assert np.all(d.sigma > 0) and d.sigma[0] > 3 * np.median(d.sigma)  # polynomial ends swing


def test_spline_derivative_tracks_a_smooth_curve():
    t = np.linspace(0, 1.0, 60)
    rng = np.random.default_rng(0)
    d = derive_omega(t, np.sin(3 * t) + rng.normal(0, 1e-3, t.size), "spline", sigma_theta=1e-3)
    inner = slice(5, -5)
    assert np.max(np.abs(d.omega[inner] - 3 * np.cos(3 * t[inner]))) < 0.1
    with pytest.raises(DatasetError):
        derive_omega(t, t, "poly5")


def test_solver_choice():
    assert auto_solver("wear", impact_scene()) == "exact"
    ok = applicable_solvers("area-rate", impact_scene())
    assert ok["exact"] is None and "series" in ok and ok["series"]
    assert applicable_solvers("wear", incline_scene())["series"]  # not on an incline
    r = fit("coulomb", synthetic("wear", {"lam": 1.2e6}), solver="series")
    assert r.status == "skipped" and "series" in r.reason


class NaNLaw(FrictionLaw):
    name = "nan-law"
    formula = "F = nan"
    citation = "test"
    params = (ParamSpec("k", "Pa s/m", 1e6, 0.0, 1e9, 1e6, "k"),)
    requires = frozenset({"u", "A"})

    def force(self, p, c):
        return np.full(np.shape(c.u), np.nan)

    def form(self, p):
        return None


def test_a_law_returning_nan_is_a_failed_result_not_an_exception():
    r = fit(NaNLaw(), synthetic("wear", {"lam": 1.2e6}), solver="ode")
    assert r.status == "failed"
    assert "NaN" in r.reason or "not finite" in r.reason


class SeriesOnly(FrictionLaw):
    """F = k A u whose force turns NaN above a threshold: fits that wander there are penalized."""

    name = "touchy"
    formula = "F = k A u (NaN for k > 3e6)"
    citation = "test"
    params = (ParamSpec("k", "Pa s/m", 1e6, 0.0, 1e9, 1e6, "k"),)
    requires = frozenset({"u", "A"})

    def force(self, p, c):
        return (p["k"] if p["k"] <= 3e6 else np.nan) * c.A * c.u

    def form(self, p):
        return AreaSlipForm(p["k"]) if p["k"] <= 3e6 else None


def test_solver_errors_during_the_search_are_penalized_and_noted():
    r = fit(SeriesOnly(), synthetic("wear", {"lam": 1.2e6}), solver="ode")
    assert r.ok and within(r.params["k"], 1.2e6)
    assert any("penalized" in n for n in r.notes)


def test_kinds_without_predictor_and_contact_area_are_skipped():
    ds = synthetic("wear", {"lam": 1.2e6})
    import attrs

    outcome = attrs.evolve(ds, kind="pendulum", name="outcome")  # a kind nobody predicts
    r = fit("wear", outcome)
    assert r.status == "skipped" and "no predictor for dataset kind 'pendulum'" in r.reason
    area = attrs.evolve(ds, kind="contact-area", name="area")
    assert fit("wear", area).status == "skipped"


def test_bad_input_is_a_one_line_error_naming_the_field():
    ds = synthetic("wear", {"lam": 1.2e6})
    with pytest.raises(ParameterError, match="lam2"):
        fit("wear", ds, fixed={"lam2": 1.0})
    with pytest.raises(ParameterError, match="x0"):
        fit("wear", ds, free={"x0": (0, 1)})
    with pytest.raises(ParameterError, match="u0"):
        fit("wear", ds, free={"u0": (3.0, 1.0)})
    with pytest.raises(FrictionLabError, match="solver"):
        fit("wear", ds, solver="magic")
    with pytest.raises(DatasetError, match="column"):
        fit("wear", ds, observable="v")


def test_degenerate_fit_takes_errors_and_correlations_from_the_identifiable_part():
    """couette with eta, h and u0 free is wear with lambda and u0 free: same errors, no spurious r = 1."""
    ds = synthetic("wear", {"lam": 1.2e6}, impact_scene(u0=12.0), truth_scene=impact_scene(u0=10.0))
    free = {"u0": (5.0, 14.0)}
    c = fit("couette", ds, solver="exact", free=free)
    w = fit("wear", ds, solver="exact", free=free)
    assert c.ok and w.ok
    assert c.stderr("u0") == pytest.approx(w.stderr("u0"), rel=0.05)
    assert c.stderr("eta/h") == pytest.approx(w.stderr("lam"), rel=0.05)
    assert c.correlations[("eta/h", "u0")] == pytest.approx(w.correlations[("lam", "u0")], abs=0.02)
    # the one strong correlation is the real one (lambda with u0), not eta or h with anything
    assert [(a, b) for a, b, _ in c.identifiability.high_correlations] == [("eta/h", "u0")]
    assert [(a, b) for a, b, _ in w.identifiability.high_correlations] == [("lam", "u0")]


def test_fit_report_names_both_aic_conventions_and_the_laws_bounds():
    """fit_report()'s AIC is ours (-2 ln L + 2k); lmfit's minimizer_result.aic (n ln(chi2/n) + 2k) is named
    beside it with its value; the law's bounds are shown where lmfit's say inf."""
    import math

    from frictionlab import fit as _fit

    r = _fit("wear", "impact-golf-v28", solver="series")
    text = r.fit_report()
    n, k, chi2 = r.stats.n_points, r.stats.n_free, r.minimizer_result.chisqr
    assert math.isclose(r.minimizer_result.aic, n * math.log(chi2 / n) + 2 * k, rel_tol=1e-9)
    assert f"Akaike info crit   = {r.stats.aic:.6g}  (-2 ln L + 2k" in text
    assert f"minimizer_result.aic = {r.minimizer_result.aic:.6g} is n ln(chi2/n) + 2k" in text
    assert "lam: Pa s/m, bounds [0, 1e+13]" in text and r.to_dataframe()["upper"].iloc[0] == 1e13


def test_a_flag_and_what_it_did_to_the_rank_are_in_the_ranking_frame():
    import pandas as pd

    from frictionlab.inference.fitting.frames import ranking_frame
    from frictionlab.inference.verdicts.ranking import RankRow

    class C:
        datasets, groups = (), ()
        ranking = (RankRow("d", "area-rate", "exact", 10, 2, aic=1.0, rank=2, flags=("rests on eta_prime",)),
                   RankRow("d", "coulomb", "exact", 10, 1, aic=5.0, rank=1))
    df = ranking_frame(C())
    assert isinstance(df, pd.DataFrame) and list(df["plausibility_flags"]) == ["rests on eta_prime", ""]
    assert df["rank_effect"].iloc[0].startswith("ranked after every unflagged") and df["rank_effect"].iloc[1] == ""


def test_a_parameter_without_effect_does_not_stop_the_others_short_of_their_minimum(monkeypatch):
    """Area-rate with eta' of no effect on the data predicts what Coulomb does, so at its minimum its
    chi-square is Coulomb's. lmfit's Levenberg-Marquardt with eta' free, from the fit's starts, stopped at
    mu = 0.0939, chi-square 27.044, where Coulomb reaches 27.021 at mu = 0.0925 (kharaz2001-tangential-cor); the
    fit then refits the others with such a parameter held, says so in its notes, and ends at Coulomb's minimum.
    The batched starts (``batchfit.best_start``) reach it directly; without them the refit must."""
    from frictionlab.inference.fitting import batch as batchfit

    ds = "kharaz2001-tangential-cor"
    coulomb = fit("coulomb", ds)
    for batched in (True, False):
        if not batched:
            monkeypatch.setattr(batchfit, "best_start", lambda *a, **k: None)
        area = fit("area-rate", ds)
        assert area.identifiability.no_effect == ("eta_prime",)
        assert area.stats.chisqr <= coulomb.stats.chisqr * (1 + 1e-6)
        assert area.params["mu"].value == pytest.approx(coulomb.params["mu"].value, abs=0.01 * coulomb.params["mu"].stderr)
    assert any("stopped short of the minimum beside eta_prime" in n for n in area.notes)
    held = fit("area-rate", ds, fixed={"eta_prime": area.params["eta_prime"].value})  # the same minimum
    assert area.stats.chisqr <= held.stats.chisqr * (1 + 1e-6)
    steady = fit("area-rate", "incline-oil-a100")  # eta' without effect, Levenberg-Marquardt at the minimum
    assert not any("stopped short" in n for n in steady.notes)


def test_a_fit_with_every_parameter_held_is_scored_where_the_noise_is_estimated():
    """Nothing to fit on a dataset whose sigma is estimated from the data (the goodness test then has a
    Jacobian with no columns): the result at the held values, not an IndexError."""
    r = fit("couette", "kharaz2001-spin", fixed={"eta": 30.0, "h": 2.5e-8})
    assert r.ok and r.stats.n_free == 0 and math.isfinite(r.stats.chisqr)
    assert 0.0 < r.goodness.chi2_p < 1.0
