"""Noise that is not declared: estimated from the data without a law, noise-free reconstructions judged on their
stated numbers, and verdicts that do not depend on a guessed sigma or on how densely a curve was sampled."""
import math
import shutil

import attrs
import numpy as np
import pytest

import frictionlab as fl
from frictionlab import fit, load_dataset
from frictionlab.inference.equivalence.family import holm
from frictionlab.io.datagen.golf import FRAME, STATED, spin_curve
from frictionlab.io.noise import estimate, gsjs, replicate_spread


def test_gsjs_is_unbiased_on_a_curve_with_uneven_sampling_and_its_df_is_right():
    rng = np.random.default_rng(2)
    t = np.sort(rng.uniform(0, 1, 41))
    s2 = np.array([gsjs(t, 5 * np.sin(3 * t) + rng.normal(0, 0.3, t.size)).sigma ** 2 for _ in range(3000)])
    assert s2.mean() / 0.09 == pytest.approx(1.0, abs=0.03)
    nu = gsjs(t, np.zeros_like(t) + rng.normal(0, 1, t.size)).df
    assert 2 * s2.mean() ** 2 / s2.var() == pytest.approx(nu, rel=0.15)  # Satterthwaite df matches the spread


def test_replicates_give_sigma_from_their_spread():
    keys = [1, 1, 1, 2, 2, 3, 3, 3]
    y = np.array([1.0, 1.2, 0.8, 5.0, 5.4, 9.0, 9.1, 8.9])
    est = replicate_spread(keys, y)
    ss = 0.08 + 0.08 + 0.02
    assert est.method == "replicates" and est.df == 5 and est.sigma == pytest.approx(math.sqrt(ss / 5))
    cols = {"speed": np.full(8, 3.0), "incidence": np.array(keys, float), "rebound_spin": y}
    assert estimate(cols, "rebound_spin").method == "replicates"


def _copy(tmp_path, name, old, new):
    src = fl.io.dataset.builtin_dir()
    for ext in (".toml", ".csv"):
        shutil.copy(src / f"{name}{ext}", tmp_path / f"{name}{ext}")
    p = tmp_path / f"{name}.toml"
    text = p.read_text()
    assert old in text
    p.write_text(text.replace(old, new, 1))
    return p


def test_a_dataset_without_noise_table_loads_as_estimated_and_the_old_assumed_means_estimated(tmp_path):
    p = _copy(tmp_path, "incline-oil-a100", '[noise]\nkind = "known"\nv = "3 mm/s"\n', "")
    d = load_dataset(p)
    assert d.noise_kind == "estimated" and "no measured sigma declared" in d.noise_note
    assert d.sigma == pytest.approx(0.003, rel=0.25)  # the generating sigma, from the data alone
    p2 = _copy(tmp_path, "incline-oil-a200", 'kind = "known"\nv = "3 mm/s"', 'kind = "assumed"\nv = "30 mm/s"')
    d2 = load_dataset(p2)
    assert d2.noise_kind == "estimated" and "'assumed' is read as estimated" in d2.noise_note
    assert d2.sigma == pytest.approx(0.003, rel=0.25) and "declared v sigma is ignored" in d2.noise_note


def test_a_sigma_declared_ten_times_too_large_changes_no_verdict_once_it_is_not_trusted(tmp_path):
    """The same data with the true sigma declared (known) and with ten times it as a guess ('assumed', read as
    estimated): the same best law, the same fit verdicts, the same equivalence verdicts."""
    true = fl.compare(laws=["coulomb", "wear", "area-rate"], datasets=["incline-oil-a100"], transfer=False,
                      bootstrap=0)
    p = _copy(tmp_path, "incline-oil-a100", 'kind = "known"\nv = "3 mm/s"', 'kind = "assumed"\nv = "30 mm/s"')
    guess = fl.compare(laws=["coulomb", "wear", "area-rate"], datasets=[str(p)], transfer=False, bootstrap=0)
    (a,), (b,) = true.answers, guess.answers
    assert (a.best, a.fits, a.equivalence) == (b.best, b.fits, b.equivalence) and a.fits
    verdicts = [[(e.law_a, e.law_b, e.verdict, e.p_a < e.p_b) for e in c.equivalence] for c in (true, guess)]
    assert verdicts[0] == verdicts[1] and len(verdicts[0]) == 2, verdicts
    assert guess.equivalence[0].noise == "estimated" and true.equivalence[0].noise == "known"
    fits_a = {f.law: f.goodness.fits for f in true.fits}
    fits_b = {f.law: f.goodness.fits for f in guess.fits}
    assert fits_a == fits_b and fits_a["coulomb"] is False


def test_a_reconstruction_gives_the_same_evidence_at_any_sampling_density():
    """The golf curve at 51 points (10 us) and at 201 points: fitted on the same four stated numbers, every law's
    chi-square, AIC and verdict are the same (a dense curve is drawn for figures, not counted as evidence)."""
    base = load_dataset("impact-golf-v28")
    s = STATED[28]
    curve = spin_curve(s)
    out = {}
    for n in (51, 201):
        t = np.linspace(0.0, s["t_c"], n)
        cols = {"t": t, "omega": curve(t), "theta": curve.antiderivative()(t)}
        ds = attrs.evolve(base, columns=cols)
        out[n] = {law: fit(law, ds) for law in ("wear", "area-rate", "coulomb")}
    for law in out[51]:
        a, b = out[51][law], out[201][law]
        assert a.stats.n_points == b.stats.n_points == 4
        assert a.stats.aic == pytest.approx(b.stats.aic, rel=1e-9) and a.goodness.fits == b.goodness.fits
    assert FRAME == 10e-6


def test_holm_steps_down_across_members():
    assert holm([0.01, 0.04, 0.03]) == [True, False, False]  # 0.01 < 0.05/3; 0.03 > 0.05/2 stops
    assert holm([0.01, 0.02, 0.04]) == [True, True, True]  # 0.01 < 0.0167, 0.02 < 0.025, 0.04 < 0.05
    assert holm([0.03, 0.03]) == [False, False]  # each alone below 0.05, neither after Holm


def _impact(truth: str, sigma: float, seed: int, estimated: bool):
    from _fit_helpers import TRUTH, impact_scene

    from frictionlab.io.dataset import Provenance

    scene = impact_scene()
    t = np.linspace(0.0, scene.duration, 41)
    y = fl.simulate(truth, scene, TRUTH[truth], solver="exact", t=t).omega + np.random.default_rng(seed).normal(0, sigma, 41)
    cols = {"t": t, "omega": y}
    kw = {"noise": {"omega": sigma}, "noise_kind": "known"}
    if estimated:
        est = estimate(cols, "omega")
        kw = {"noise": {"omega": est.sigma}, "noise_kind": "estimated", "noise_df": {"omega": est.df},
              "noise_est": {"omega": est}}
    return fl.Dataset(name=f"kt-{truth}", kind="impact", observable="omega", path=None, columns=cols,
                      units={"t": "s", "omega": "rad/s"}, scene=scene, fixed={},
                      provenance=Provenance("synthetic", "tests", seed=seed), **kw)


@pytest.mark.parametrize("estimated", [False, True])
def test_the_papers_pair_on_known_truth_rejects_the_false_law_and_keeps_the_true_one(estimated):
    """Wear truth: at a quarter of the pair's threshold noise the test rejects area-rate (never wear); at four
    times it, it rejects neither. With sigma measured and with sigma estimated from the data."""
    from frictionlab import analyze_equivalence

    thr = 41.6  # rad/s: the pair's threshold on wear's noise-free curve (benchmarks/calibration.py prints it)
    low = _impact("wear", thr / 4, 7, estimated)
    e = analyze_equivalence(fit("wear", low), fit("area-rate", low))
    assert e.verdict == "different" and e.p_b < 0.025 <= e.p_a, e.explanation
    assert e.threshold == pytest.approx(thr, rel=0.3)  # from the noisy fits: near the noise-free value
    high = _impact("wear", 4 * thr, 8, estimated)
    e = analyze_equivalence(fit("wear", high), fit("area-rate", high))
    assert e.verdict != "different" and e.p_a >= 0.025, e.explanation


def test_golf_answer_states_the_quantitative_and_the_qualitative_verdict_from_the_stated_numbers():
    """Exact wear and area-rate both miss the four stated numbers: no test. The truncated series fits them at
    28 m/s and is told apart from area-rate; its peak time is a quantitative difference, not a feature."""
    c = fl.compare(laws=["wear", "area-rate"], datasets=["impact-golf-v28"], transfer=False, bootstrap=0)
    (a,) = c.answers
    assert a.short["equivalence"].startswith("both fail their fit tests (exact); different (p = "), a.short
    assert "qualitatively equivalent on some, not all" in a.short["equivalence"]
    assert "peak times 33 µs apart (quantitative)" in a.short["qualitative"] and a.qualitative.startswith("Qualitatively")
    series = next(e for e in c.equivalence if e.solver_a == "series")
    assert series.qualitative["verdict"] == "qualitatively equivalent" and series.qualitative["peak_time"]["differs"]
    e = next(e for e in c.equivalence if e.solver_a == "exact" and e.law_b == "area-rate")
    assert e.observable == "stated" and e.n_points == 4  # four stated numbers, not 51 curve points
    assert e.qualitative["features"]["data"]["t_peak"] == pytest.approx(260e-6)
    assert e.qualitative["features"]["wear"]["peak"] is False  # the exact wear spin has no peak before t_c


def test_a_noise_value_without_kind_is_an_error_naming_the_file_and_the_two_kinds(tmp_path):
    """A sigma written without saying whether it was measured would be silently ignored: refused instead. A
    table with only a kind, or with the correlation model another part of the loader reads, is not refused."""
    p = _copy(tmp_path, "incline-oil-a100", 'kind = "known"\nv = "3 mm/s"', 'v = "3 mm/s"')
    from frictionlab.core.errors import DatasetError

    with pytest.raises(DatasetError, match=r'incline-oil-a100\.toml: \[noise\] gives v without kind: add kind = '
                                              r'"known" .* or kind = "estimated"'):
        load_dataset(p)
    p.write_text(p.read_text().replace('v = "3 mm/s"', 'kind = "estimated"\ncorrelation = "ar1"'))
    assert load_dataset(p).noise_kind == "estimated"
