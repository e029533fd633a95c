"""Noise chosen by the data (inference.noise): AR(p) by BIC and Burg, ARMA(1,1) where the order runs to its cap,
the exact whitened likelihood, the law-fit test of bands after a step, Vuong's test, and the velocity-step fit
under the data's noise model."""
from __future__ import annotations

import math
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from frictionlab.inference.diagnostics.goodness import ljung_box
from frictionlab.inference.noise import arp
from frictionlab.inference.noise.misfit import band_test
from frictionlab.inference.verdicts.vuong import long_run_variance, vuong

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))


def test_bic_and_burg_recover_an_ar2_and_its_whitened_residuals_are_white():
    truth = arp.from_coefficients((0.6, -0.3))
    x = arp.draw(np.random.default_rng(1), truth, 20000)
    model, var = arp.select(x, 100.0)
    assert model.name == "AR(2)" and not model.capped
    assert model.ar == pytest.approx((0.6, -0.3), abs=0.03) and var == pytest.approx(1.0, rel=0.05)
    assert ljung_box(arp.whiten(x, model), model.n_coef) > 0.01
    assert ljung_box(x, 0) < 1e-10  # the data themselves are far from white


def test_an_order_that_runs_to_its_cap_is_replaced_by_arma11():
    truth = arp.from_coefficients((0.5,), ma=0.8)  # an AR(infinity) tail of (-0.8)^j: no short AR order describes it
    x = arp.draw(np.random.default_rng(2), truth, 5000)
    model, _ = arp.select(x, 10.0)  # cap 6 at 10 Hz
    assert arp.order_cap(10.0, 5000) == 6 and model.capped
    assert model.name == "ARMA(1,1)" and model.ar[0] == pytest.approx(0.5, abs=0.05)
    assert model.ma == pytest.approx(0.8, abs=0.05)


def test_the_whitened_likelihood_is_the_exact_multivariate_normal_one():
    from scipy.linalg import toeplitz
    from scipy.signal import lfilter
    from scipy.stats import multivariate_normal

    model = arp.from_coefficients((0.5, 0.1, -0.3))
    n = 40
    x = arp.draw(np.random.default_rng(3), model, n, sigma=2.0)
    h = lfilter([1.0], np.concatenate([[1.0], -np.asarray(model.ar)]), np.r_[1.0, np.zeros(4000)])
    gamma = np.array([h[:4000 - k] @ h[k:4000] for k in range(n)]) * 4.0
    exact = -2 * multivariate_normal(np.zeros(n), toeplitz(gamma)).logpdf(x)
    w = arp.whiten(x, model)
    mine = float(w @ w) / 4.0 + n * math.log(2 * math.pi * 4.0) + arp.log_det(model, n)
    assert mine == pytest.approx(exact, rel=1e-9)


def _step_record(n_before=2000, n_after=3000, dc=10.0, v=10.0, rate=100.0):
    t = np.arange(n_before + n_after) / rate
    ts = n_before / rate
    x = np.where(t < ts, 3.0 * t, 3.0 * ts + v * (t - ts))
    return t, x, ts


def test_bands_pass_white_residuals_and_name_the_band_a_misfit_leaves():
    t, x, ts = _step_record()
    rng = np.random.default_rng(4)
    alarms = sum(band_test(rng.standard_normal(t.size), t, x, [ts], 10.0).p < 0.01 for _ in range(100))
    assert alarms <= 4  # 1 % nominal, Bonferroni: conservative
    w = rng.standard_normal(t.size)
    slip = x - 3.0 * ts
    w[(t >= ts) & (slip >= 10.0) & (slip < 30.0)] += 0.5  # a misfit between 1 and 3 Dc after the step
    r = band_test(w, t, x, [ts], 10.0)
    assert r.p < 0.01 and r.band == "1-3 Dc after step 1" and r.what == "mean"


def test_the_newey_west_variance_of_ar1_approaches_its_long_run_variance():
    phi = 0.5
    x = arp.draw(np.random.default_rng(5), arp.from_coefficients((phi,)), 200000)
    assert long_run_variance(x, 60) == pytest.approx(1 / (1 - phi) ** 2, rel=0.05)


def _fake_fit(law, loglik, k=5):
    d = SimpleNamespace(loglik=loglik)
    return SimpleNamespace(ok=True, law=law, per_dataset=(d,), stats=SimpleNamespace(k_lik=k))


def test_vuong_names_the_closer_law_or_says_equally_close():
    rng = np.random.default_rng(6)
    base = rng.standard_normal(4000)
    a = _fake_fit("A", -0.5 * base ** 2)
    b_far = _fake_fit("B", -0.5 * (base + 0.3) ** 2)  # B's residuals carry an offset: A is closer
    r = vuong(a, b_far)
    assert r.closer == "A" and r.z > 0 and "A is closer (p = " in r.text
    b_same = _fake_fit("B", -0.5 * base ** 2 + 1e-3 * rng.standard_normal(4000))
    r = vuong(a, b_same)
    assert r.closer == "" and "equally close at this noise" in r.text


def test_a_velocity_step_fit_chooses_the_noise_model_and_keeps_the_two_questions_apart(tmp_path):
    import frictionlab as fl
    from calibration_vuong import AGING, data_of, make_dataset, truth

    ds, x, v1 = make_dataset(tmp_path, 3.0)
    curve = truth(ds, x, v1, AGING)
    noise = arp.draw(np.random.default_rng(7), arp.from_coefficients((0.6, -0.2)), curve.size, 3e-4)
    f = fl.fit(AGING, data_of(ds, curve + noise), trend=True, stiffness=True)
    row = f.velstep.rows[0]
    assert row.noise == (("100 Hz", "AR(2)"),) and "white" in row.whiteness
    assert f.goodness.fits and f.goodness.noise_ok and math.isnan(f.goodness.chi2_p)
    assert abs(f.value("a") - 0.009) < 3 * f.params["a"].stderr
    assert abs(f.value("Dc") - 10e-6) < 3 * f.params["Dc"].stderr
    # the per-sample log-likelihoods add up to the fit's -2 ln L
    assert -2 * float(np.sum(f.per_dataset[0].loglik)) == pytest.approx(f.stats.neg2loglik, rel=1e-12)
    # a misfit: the slip law on an aging record with a large step leaves structure in a named band
    ds30, x30, v30 = make_dataset(tmp_path, 30.0)
    aging30 = truth(ds30, x30, v30, AGING)
    g = fl.fit("rate-state-slip", data_of(ds30, aging30 + noise[:aging30.size]), trend=True, stiffness=True).goodness
    assert g.fits is False and "Dc after step 1" in g.band


def _seasonal(rng, n, lag=12, scale=1e-3):
    """x_t = e_t + 0.9 e_{t-lag}: correlation at a lag of its own that no AR order up to the cap nor ARMA(1,1)
    whitens."""
    e = rng.standard_normal(n + lag)
    return scale * (e[lag:] + 0.9 * e[:-lag])


def test_noise_no_candidate_whitens_gets_an_ar1_working_model_and_whitenable_noise_keeps_its_choice():
    from frictionlab.inference.noise.record import RecordNoise

    t = np.arange(3500) / 100.0
    rec = RecordNoise.of(t, 1e-3)
    rec.estimate(_seasonal(np.random.default_rng(0), t.size))
    m = rec.models[0]
    assert rec.robust and m.name == "AR(1)" and m.best.name == "AR(12)"
    assert m.robust.startswith("AR(12), ARMA(1,1) and AR(20) leave the residuals correlated (Ljung-Box p = ")
    assert rec.describe()[0][1].startswith("AR(1) working model: AR(12), ARMA(1,1) and AR(20) leave")
    rec.estimate(arp.draw(np.random.default_rng(1), arp.from_coefficients((0.6, -0.2)), t.size))
    assert rec.models[0].robust  # kept for the rest of the fit once chosen
    fresh = RecordNoise.of(t, 1e-3)
    fresh.estimate(arp.draw(np.random.default_rng(1), arp.from_coefficients((0.6, -0.2)), t.size))
    assert not fresh.robust and fresh.models[0].name == "AR(2)"


def test_arma11_is_the_next_candidate_where_bics_ar_order_leaves_the_residuals_correlated():
    from frictionlab.inference.noise.record import RecordNoise

    t = np.arange(5000) / 100.0
    chosen = []
    for seed in range(12):
        x = arp.draw(np.random.default_rng(seed), arp.from_coefficients((0.5,), ma=0.8), t.size)
        first = arp.select(x, 100.0)[0]
        rec = RecordNoise.of(t, 1.0)
        rec.estimate(x)
        assert not rec.robust and first.kind == "AR" and not first.capped  # BIC's order stays below the cap of 20
        chosen.append(rec.models[0].name)
    assert "ARMA(1,1)" in chosen and all(c == "ARMA(1,1)" or c.startswith("AR(") for c in chosen)


def test_the_compiled_pass_whitens_an_ar1_record_exactly_as_the_filter_does():
    from frictionlab.inference.noise.record import RecordNoise
    from frictionlab.inference.velstep.kernel import basis_sums

    rng = np.random.default_rng(4)
    t = np.concatenate([np.arange(300) / 10.0, 30.0 + np.arange(1, 501) / 100.0])
    rec = RecordNoise.of(t, 1.0)
    rec.models = [arp.from_coefficients((0.7,)), arp.from_coefficients((-0.3,))]
    rec.sigma_g = np.array([2e-3, 1e-3])
    y, m, S = rng.standard_normal(t.size), rng.standard_normal(t.size), rng.standard_normal((t.size, 4))
    Q = np.linalg.qr(rng.standard_normal((t.size, 2)))[0]
    got = basis_sums(y, 0.1, m, S, *rec.ar1_form(), Q)
    W = rec.whiten(np.column_stack([0.1 + m - y, S, np.ones(t.size)]) / rec.sigma[:, None])
    w, D = W[:, 0], W[:, 1:]
    for a, b in zip(got, (float(w @ w), D.T @ w, D.T @ D, Q.T @ w, Q.T @ D)):
        assert np.allclose(a, b, rtol=1e-10, atol=1e-12 * np.max(np.abs(b)))
    rec.models[1] = arp.from_coefficients((0.5, -0.2))
    assert rec.ar1_form() is None


def test_a_fit_whose_noise_no_model_whitens_says_so_and_its_sandwich_error_bars_cover_the_truth(tmp_path):
    import frictionlab as fl
    from calibration_vuong import AGING, data_of, make_dataset, truth

    ds, x, v1 = make_dataset(tmp_path, 3.0)
    curve = truth(ds, x, v1, AGING)
    noise = _seasonal(np.random.default_rng(7), curve.size, scale=3e-4)
    f = fl.fit(AGING, data_of(ds, curve + noise), trend=True, stiffness=True)
    (rate, what), = f.velstep.rows[0].noise
    assert what.startswith("AR(1) working model: ") and "Newey-West sandwich" in what
    assert "working model" in f.stats.likelihood_reason
    for name, value in (("a", 0.009), ("b", 0.012), ("Dc", 10e-6)):
        assert abs(f.value(name) - value) < 4 * f.params[name].stderr


def test_nagatas_extra_column_goes_through_the_compiled_ar1_pass(tmp_path):
    """A law with a parameter beyond a, b, Dc and k (Nagata's c) on a record whose noise the data read as AR(1):
    the compiled pass carries the extra column, and the fit gives c = 0 the aging law's chi-square or better."""
    import frictionlab as fl
    from calibration_vuong import AGING, data_of, make_dataset, truth

    ds, x, v1 = make_dataset(tmp_path, 3.0)
    curve = truth(ds, x, v1, AGING)
    e = np.random.default_rng(8).normal(0.0, 2e-4, curve.size)
    for i in range(1, e.size):
        e[i] += 0.6 * e[i - 1]
    data = data_of(ds, curve + e)
    nagata, aging = fl.fit("rate-state-nagata", data, trend=True, stiffness=True), fl.fit(AGING, data, trend=True,
                                                                                          stiffness=True)
    assert nagata.status == "ok" and aging.status == "ok", nagata.reason
    assert [w for _, w in nagata.velstep.rows[0].noise] == [w for _, w in aging.velstep.rows[0].noise]
    assert nagata.stats.chisqr <= aging.stats.chisqr * (1 + 1e-6)
