"""Known-truth datasets (examples/known-truth, `frictionlab datasets rebuild --known-truth`): the verdicts of
``compare`` must match the law that generated each set, for the equivalence test, the transfer test and
goodness of fit (a law that is not registered)."""
import filecmp
import math
import json
from pathlib import Path

import pytest
from scipy.stats import chi2 as chi2_dist

from frictionlab import fit, load_dataset
from frictionlab.io.datagen import KNOWN_TRUTH, rebuild
from frictionlab.io.datagen.knowntruth import QuadraticDrag
from frictionlab.physics.registry import available_laws
from frictionlab.pipeline.comparison import compare

FOLDER = Path(__file__).resolve().parent.parent / "examples" / "known-truth"


def kt(name):
    return load_dataset(FOLDER / f"{name}.toml")


def test_folder_is_regenerated_bit_for_bit(tmp_path):
    written = rebuild(tmp_path, KNOWN_TRUTH)
    assert {p.name for p in written} == {p.name for p in FOLDER.iterdir()}
    for p in written:
        assert filecmp.cmp(p, FOLDER / p.name, shallow=False), p.name
    for p in FOLDER.glob("*.toml"):
        pv = load_dataset(p).provenance
        assert pv.kind == "synthetic" and pv.seed is not None and pv.truth["law"]
        assert pv.command == "frictionlab datasets rebuild --known-truth"


def test_equivalence_verdicts_match_the_truth():
    """wear vs couette: equivalent within the margin; coulomb vs wear: different, rejecting the law that did not
    generate the data."""
    c = compare(laws=["coulomb", "wear", "couette"], datasets=[kt("kt-coulomb-impact"), kt("kt-wear-impact")],
                solvers=["exact"], replicates=100, transfer=False)
    got = {(e.dataset, e.law_a, e.law_b): e for e in c.equivalence}
    assert len(got) == 4 and all(e.ok for e in got.values())
    for ds in ("kt-coulomb-impact", "kt-wear-impact"):
        wc = got[(ds, "wear", "couette")]  # one curve; on Coulomb's data both fail: no test of a pair that fails
        assert wc.verdict == ("equivalent within δ" if ds == "kt-wear-impact" else "both fail their fit tests"), ds
        e = got[(ds, "coulomb", "wear")]
        assert e.verdict == "different", e.explanation
        truth = kt(ds).provenance.truth["law"]
        rejected = "coulomb" if e.p_a < 0.05 else "wear"
        assert (e.p_a < 0.05) != (e.p_b < 0.05)  # exactly one law is rejected ...
        assert rejected != truth  # ... and it is not the one that generated the data


def test_where_no_law_compared_fits_no_pair_gets_a_p_value():
    """Stribeck friction on an incline: the four laws compared by default each fail their fit tests, so every pair
    of them is 'both fail their fit tests': no replicates, no p-value, no margin bound; only misfits compared."""
    c = compare(datasets=[kt("kt-stribeck-incline")], replicates=40, transfer=False)
    assert all(f.goodness.fits is False for f in c.fits if f.ok) and len([f for f in c.fits if f.ok]) == 4
    assert len(c.equivalence) == 3
    for e in c.equivalence:
        assert e.verdict == "both fail their fit tests" and not e.tested, e.explanation
        assert math.isnan(e.p) and math.isnan(e.p_adjusted) and math.isnan(e.upper) and e.t_a.size == 0
        assert "no p-value" in e.explanation and "two-sided p" not in e.explanation
    (a,) = c.answers
    assert a.equivalence == "both fail their fit tests" and a.headline.startswith("no registered law describes")


def test_transfer_verdicts_match_the_truth():
    """One lambda at two speeds: it serves both; two lambdas (the paper's situation): it does not."""
    names = ["kt-speeds-v20", "kt-speeds-v40", "kt-twolam-v20", "kt-twolam-v40"]
    c = compare(laws=["wear"], datasets=[kt(n) for n in names], solvers=["exact"], equivalence=False)
    tr = {t.group: t for t in c.transfer}
    assert set(tr) == {"kt-speeds", "kt-twolam"}
    same, two = tr["kt-speeds"].shared[0], tr["kt-twolam"].shared[0]
    assert same.serves is True and two.serves is False
    assert same.p_value > 0.05 > 1e-6 > two.p_value
    assert same.shared["lam"] == pytest.approx(1.2e6, rel=0.03)
    # predicting the other speed without refitting: within the noise for one lambda, far outside for two
    for p in tr["kt-speeds"].predictions:
        assert p.rms_sigma < 1.5, p
    for p in tr["kt-twolam"].predictions:
        assert p.rms_sigma > 5, p
    assert {(p.source, p.target) for p in tr["kt-speeds"].predictions} == {("kt-speeds-v20", "kt-speeds-v40"),
                                                                          ("kt-speeds-v40", "kt-speeds-v20")}
    assert "yes for wear [exact]" in tr["kt-speeds"].answer() and "no, for no law" in tr["kt-twolam"].answer()
    from frictionlab.inference.verdicts.answers import Answer
    from frictionlab.inference.equivalence.transfer import fill_answers

    rows = [Answer(group=g, datasets=tuple(tr[g].datasets), provenance="synthetic", best=None, fits=False, headline="",
                   goodness="", equivalence="not tested", noise_threshold="", series_vs_exact="") for g in tr]
    filled = {a.group: a for a in fill_answers(rows, c.transfer)}
    assert filled["kt-speeds"].transfer == tr["kt-speeds"].answer()
    assert filled["kt-twolam"].details["transfer"]["shared"][0]["serves"] is False
    assert filled["kt-speeds"].short["transfer"].startswith("one wear [exact] fit for both: yes (p = ")
    assert filled["kt-twolam"].short["transfer"].startswith("one wear [exact] fit for both: no (p ")


def test_a_group_of_different_observables_is_not_transferred_and_says_why():
    from frictionlab.inference.verdicts.answers import group_of
    from frictionlab.inference.equivalence.transfer import candidates_by_group, skipped

    kharaz = [load_dataset(n) for n in ("kharaz2001-spin", "kharaz2001-tangential-cor")]
    assert {group_of(d) for d in kharaz} == {"kharaz2001"}  # declared by the TOML key 'group'
    c = compare(laws=["coulomb"], datasets=kharaz, solvers=["exact"], equivalence=False)
    assert candidates_by_group(c.fits, kharaz) == {}
    (t,) = c.transfer
    assert t.status == "skipped" and "different observables (rebound_spin, cm_tangential_cor)" in t.reason
    assert t == skipped(kharaz)[0] and not t.predictions and not t.shared
    (a,) = c.answers
    assert a.group == "kharaz2001" and a.datasets == ("kharaz2001-spin", "kharaz2001-tangential-cor")
    assert a.transfer.startswith("not tested: its datasets measure different observables")
    assert a.short["transfer"] == "no transfer: different observables"


def test_unregistered_law_is_fitted_by_no_registered_law():
    ds = kt("kt-drag-impact")
    law = QuadraticDrag()
    assert law.name not in available_laws()
    assert all("|u|" not in registered.formula or "u |u|" not in registered.formula
               for registered in available_laws().values())
    for name in ("coulomb", "wear", "area-rate"):
        f = fit(name, ds)
        assert f.ok
        p = chi2_dist.sf(f.stats.chisqr, f.stats.n_points - f.stats.n_params)
        assert p < 1e-6, (name, f.stats.redchi)
    own = fit(law, ds, solver="ode", initial={"c": 1e5})  # the generating law does describe them
    assert chi2_dist.sf(own.stats.chisqr, own.stats.n_points - 1) > 0.01
    assert own.value("c") == pytest.approx(1.5e5, rel=0.05)


@pytest.mark.slow
def test_compare_command_on_the_folder_matches_every_truth(run_cli, tmp_path):
    """The whole folder through the CLI with default settings (about a minute on 2 cores)."""
    out = tmp_path / "kt"
    r = run_cli("compare", "--data", *sorted(str(p) for p in FOLDER.glob("*.toml")), "--out", str(out), "--force",
                "--bootstrap", "0", "--no-tolerance")
    assert r.returncode == 0, r.stderr
    data = json.loads((out / "results.json").read_text())
    eq = {(e["dataset"], e["law_a"], e["solver_a"], e["law_b"]): e for e in data["equivalence"]}
    for d in data["datasets"]:
        truth = d["provenance"]["truth"]["law"]
        if truth in ("stribeck", "quadratic drag F = c A u |u| (not registered)"):  # no law compared fits
            for (name, *_), e in eq.items():
                if name == d["name"]:
                    assert e["verdict"] == "both fail their fit tests" and e["p"] is None, e
            continue
        assert eq[(d["name"], "wear", "exact", "couette")]["verdict"] == (
            "both fail their fit tests" if truth == "coulomb" else "equivalent within δ")
        cw = eq[(d["name"], "coulomb", "exact", "wear")]
        assert cw["verdict"] == "different"
        if truth in ("coulomb", "wear", "couette"):
            assert (cw["p_a"] < 0.05) == (truth != "coulomb")
    # the unregistered law: no registered law (whatever is registered by then) describes its data
    drag = [f for f in data["fits"] if f["dataset"] == "kt-drag-impact" and f["status"] == "ok"]
    assert drag
    for f in drag:
        st = f["statistics"]
        assert chi2_dist.sf(st["chisqr"], st["n_points"] - st["n_params"]) < 1e-6, (f["law"], f["solver"])
    for a in data.get("answers", []):  # filled once the verdict layer is in
        if a["group"] == "kt-drag":
            assert a["headline"].startswith("no registered law describes these data"), a["headline"]
    tr = {t["group"]: t for t in data["transfer"]}
    serves = lambda g: {s["law"]: s["serves"] for s in tr[g]["shared"] if s["solver"] == "exact"}  # noqa: E731
    assert serves("kt-speeds")["wear"] is True and serves("kt-twolam")["wear"] is False
