"""AR(1) noise (inference.noise.ar1): the prewhitened likelihood against a direct evaluation, phi recovered, sampling-
rate groups, the dataset's [noise] correlation, and the calibration on synthetic steps (--quick)."""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

import frictionlab as fl
from frictionlab.core.errors import DatasetError
from frictionlab.inference.noise import ar1
from frictionlab.inference.diagnostics.goodness import ljung_box
from frictionlab.io import noise

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))


def _two_rate_times(rng):
    """10 Hz then 100 Hz, with jitter (as a basalt record is logged), 60 samples."""
    slow = np.cumsum(0.1 * (1 + 0.1 * rng.uniform(-1, 1, 20)))
    fast = slow[-1] + np.cumsum(0.01 * (1 + 0.1 * rng.uniform(-1, 1, 40)))
    return np.concatenate([slow, fast])


def test_rate_groups_split_a_record_logged_at_two_rates():
    t = _two_rate_times(np.random.default_rng(0))
    labels, refs = ar1.rate_groups(t)
    assert refs.size == 2 and refs[0] == pytest.approx(0.01, rel=0.1) and refs[1] == pytest.approx(0.1, rel=0.1)
    assert list(labels[:20]) == [1] * 20 and list(labels[21:]) == [0] * 39
    phi = ar1.coefficients(t, labels, refs, np.array([0.6, 0.3]))
    assert phi[0] == 0.0 and phi[20] == 0.0  # the first sample of each rate's run is at its marginal variance
    dt = np.diff(t)
    assert phi[25] == pytest.approx(0.6 ** (dt[24] / refs[0]))


def test_whitened_likelihood_equals_the_direct_multivariate_normal():
    """-2 ln L = sum w^2 + sum ln(2 pi sigma_i^2) + sum ln(1 - phi_i^2) with w the prewhitened residuals equals
    -2 log of the Gaussian density with the AR(1) covariance sigma_i sigma_j prod_{k=i+1..j} phi_k."""
    from scipy.stats import multivariate_normal

    rng = np.random.default_rng(1)
    t = _two_rate_times(rng)
    labels, refs = ar1.rate_groups(t)
    phi = ar1.coefficients(t, labels, refs, np.array([0.7, 0.4]))
    sigma = np.where(labels == 0, 8e-4, 6e-4)
    n = t.size
    cov = np.empty((n, n))
    for i in range(n):
        for j in range(i, n):
            cov[i, j] = cov[j, i] = sigma[i] * sigma[j] * np.prod(phi[i + 1:j + 1])
    e = ar1.draw(rng, sigma, phi)
    w = ar1.whiten(e / sigma, phi)
    mine = float(w @ w) + float(np.sum(np.log(2 * math.pi * sigma ** 2))) + ar1.log_det(phi)
    assert mine == pytest.approx(-2 * multivariate_normal(np.zeros(n), cov).logpdf(e), rel=1e-10)


def test_draws_have_the_model_s_autocorrelation_and_phi_is_recovered():
    rng = np.random.default_rng(2)
    t = np.arange(40000) * 0.01
    labels, refs = ar1.rate_groups(t)
    phi = ar1.coefficients(t, labels, refs, np.array([0.6]))
    e = ar1.draw(rng, np.full(t.size, 1e-3), phi)
    assert np.corrcoef(e[1:], e[:-1])[0, 1] == pytest.approx(0.6, abs=0.015)
    assert e.std() == pytest.approx(1e-3, rel=0.03)
    assert ar1.estimate_phi(e, t, labels, refs)[0] == pytest.approx(0.6, abs=0.01)
    sigma, ests = ar1.noise_sigma(t, 0.6 + e, phi, labels, refs)  # GSJS of the prewhitened data: sigma itself
    assert sigma[0] == pytest.approx(1e-3, rel=0.03) and ests[0].df > 10000


def test_independent_replicate_noise_is_drawn_as_before():
    """Without ar1 the replicates' noise is rng.standard_normal(n) * sigma, draw for draw."""
    ds = fl.load_dataset("spring-slider-aging")
    y = ds.y
    a = ar1.noise_drawer(ds, y, y, 2e-4)(np.random.default_rng(7))
    b = np.random.default_rng(7).standard_normal(y.size) * 2e-4
    assert np.array_equal(a, b)


def _dataset(tmp_path, noise_lines):
    src = fl.load_dataset("spring-slider-aging").path
    text = src.read_text().replace('[noise]\nkind = "known"\nmu = 0.0001\n', "[noise]\n" + noise_lines)
    (tmp_path / "d.toml").write_text(text)
    (tmp_path / "d.csv").write_text(src.with_suffix(".csv").read_text())
    return tmp_path / "d.toml"


def test_noise_correlation_is_read_from_the_noise_table(tmp_path):
    assert fl.load_dataset("spring-slider-aging").noise_correlation == "none"
    path = _dataset(tmp_path, 'kind = "estimated"\ncorrelation = "ar1"\n')
    assert fl.load_dataset(path).noise_correlation == "ar1"
    path = _dataset(tmp_path, 'kind = "estimated"\ncorrelation = "white"\n')
    with pytest.raises(DatasetError, match=r"d.toml: noise.correlation = 'white', expected one of none, ar1"):
        fl.load_dataset(path)


def test_a_fit_of_ar1_data_profiles_phi_and_tests_the_prewhitened_residuals(tmp_path):
    path = _dataset(tmp_path, 'kind = "estimated"\ncorrelation = "ar1"\n')
    f = fl.fit("rate-state-aging", path)
    assert f.ok and "phi" in f.params and f.params["phi"].kind == "noise"
    assert math.isfinite(f.goodness.white_p) and "whiteness p" in f.goodness.text
    assert f.stats.k_lik == f.stats.n_params + 1  # phi counts in the information criteria
    d = f.per_dataset[0]
    labels, refs = ar1.rate_groups(d.target.t)
    phi = ar1.coefficients(d.target.t, labels, refs, np.array([f.value("phi")]))
    z = ar1.whiten(d.residual / d.target.sigma, phi)
    assert f.stats.chisqr == pytest.approx(float(z @ z), rel=1e-9)
    direct = float(z @ z) + float(np.sum(np.log(2 * math.pi * d.target.sigma ** 2))) + ar1.log_det(phi)
    assert f.stats.neg2loglik == pytest.approx(direct, rel=1e-12)


def test_ljung_box_tells_white_from_correlated_noise():
    rng = np.random.default_rng(3)
    white = [ljung_box(rng.standard_normal(2000), 0) for _ in range(200)]
    assert 0.35 < float(np.mean(white)) < 0.65 and np.mean(np.array(white) < 0.05) < 0.1
    t = np.arange(2000.0)
    phi = np.r_[0.0, np.full(1999, 0.3)]
    assert ljung_box(ar1.draw(rng, np.ones(2000), phi), 0) < 1e-6


def test_ratio_pvalue_in_chunks_draws_as_one_block(monkeypatch):
    rng = np.random.default_rng(4)
    t = np.sort(rng.uniform(0, 10, 300))
    est = noise.gsjs(t, rng.standard_normal(300))
    J = rng.standard_normal((300, 4))
    whole = noise.ratio_pvalue(est, 310.0, J)
    monkeypatch.setattr(noise, "CHUNK_FLOATS", 300 * 7)
    assert noise.ratio_pvalue(est, 310.0, J) == whole


@pytest.mark.parametrize("c_over_n", [0.95, 1.0, 1.08, 1.15])
def test_moment_ratio_pvalue_agrees_with_the_monte_carlo_one(monkeypatch, c_over_n):
    rng = np.random.default_rng(5)
    n = 400
    t = np.sort(rng.uniform(0, 10, n))
    est = noise.gsjs(t, rng.standard_normal(n))
    J = rng.standard_normal((n, 5))
    monkeypatch.setattr(noise, "DRAWS", 20000)
    mc = noise.ratio_pvalue(est, c_over_n * n, J)
    se = math.sqrt(mc * (1 - mc) / 20000)
    assert noise.ratio_pvalue_moments(est, c_over_n * n, J) == pytest.approx(mc, abs=4 * se + 2e-3)


def test_calibration_quick_covers_and_rarely_alarms():
    """benchmarks/calibration_ar1.py --quick: 12 synthetic steps at phi 0 and 0.6 fitted with the AR(1) model cover
    the true a, b, Dc in most fits and raise few false alarms (the full table is printed by the script)."""
    import calibration_ar1

    rows = calibration_ar1.run(12, [0.0, 0.6], seed=0, quick=True, models=("ar1",))
    for r in rows:
        assert r["n"] == 12
        assert min(r["a"], r["b"], r["Dc"]) >= 8, r
        assert r["alarms"] <= 3, r
    assert "coverage a" in calibration_ar1.table(rows)
