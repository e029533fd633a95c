"""The report's first screen: the verdict table from Comparison.answers, the series finding, escaping."""
import math

import attrs
import numpy as np
import pytest
from _fit_helpers import synthetic

from frictionlab import compare
from frictionlab.inference.verdicts.answers import Answer
from frictionlab.inference.equivalence.discrimination import sentence
from frictionlab.report import build, first_screen
from frictionlab.report.render import html_page, markdown


@pytest.fixture(scope="module")
def comp():
    ds = synthetic("wear", {"lam": 1.81e6}, seed=5, n=26, name="impact-<b>bold</b>")
    ds = attrs.evolve(ds, description="A <script>alert(1)</script> & <i>raw</i> description")
    return compare(laws=["wear", "area-rate"], datasets=[ds])


def _first(c):
    sections, extra = build(c, modules=[first_screen])
    return sections, extra


def test_series_slip_crosses_zero_where_the_closed_form_says():
    # u = u0 (1 - b + b cos(phi t)) is zero at cos(phi t) = (b - 1) / b
    b, tc = 0.81, 500e-6
    t = np.linspace(0.0, tc, 5001)
    u = 12.0 * (1 - b + b * np.cos(math.pi / tc * t))
    expected = math.acos((b - 1) / b) / (math.pi / tc)
    assert first_screen.slip_zero(t, u) == pytest.approx(expected, abs=1e-9)
    assert first_screen.slip_zero(t, np.abs(u) + 1.0) is None


def test_finding_computed_from_the_fitted_series(comp):
    (f,) = first_screen.series_findings(comp)
    b = f.series.per_dataset[0].trajectory("wear", np.array([0.0])).info["b"]
    expected = math.acos((b - 1) / b) / (math.pi / f.contact_time)
    assert f.t_cross == pytest.approx(expected, rel=1e-4)
    assert f.full.solver == "exact" and f.full_min_slip > 0  # the exact slip never reaches zero
    sections, extra = _first(comp)
    assert extra["series_slip_zero_s"][f.dataset.name] == f.t_cross
    md = markdown("t", sections)
    assert "figures/finding.png" in md
    # the series is not among the top-ranked candidates here: no slip panel, no story of its crossing
    top = {r.candidate for r in comp.ranking if r.rank == 1}
    assert "wear [series]" not in top and f"cross zero at {f.t_cross * 1e6:.4g} µs" not in md


def test_without_answers_nothing_is_declared_to_fit(comp):
    md = markdown("t", _first(attrs.evolve(comp, answers=()))[0])
    assert "`Comparison.answers` is empty)" in md and "lowest AIC (not a fit test)" in md
    assert "Not in this comparison: a goodness-of-fit test." in md
    assert "misses it by χ² 3.84" in md  # the discrimination test's threshold is shown


def test_answers_are_rendered_and_empty_columns_said(comp):
    a = Answer(group="impact", datasets=("impact-x",), provenance="synthetic", best="wear [exact]", fits=True,
               headline="best: wear [exact]", goodness="chi2 p = 0.41", equivalence="different",
               noise_threshold="", series_vs_exact="the series' slip crosses zero at 309 us", transfer="",
               details={"plausibility": ["eta' = -7.9e11 N s/m^2 is negative"]})
    md = markdown("t", _first(attrs.evolve(comp, answers=(a,)))[0])
    head = next(line for line in md.splitlines() if line.startswith("| dataset group"))
    assert "best law" in head and "goodness of fit" in head and "noise threshold" not in head
    absent = first_screen.ABSENT
    assert (f"Not in this comparison: a noise threshold; {absent['accuracy']}; one parameter set across conditions "
            "(no group of two or more datasets).").replace("`", "") in md.replace("`", "")
    assert "chi2 p = 0.41" in md and "**Implausible.** eta' = -7.9e11" in md
    assert "`Comparison.answers` is empty" not in md


def test_groups_without_a_fitted_law_fold_into_one_line_under_the_table(comp):
    kw = dict(provenance="synthetic", fits=False, goodness="", equivalence="not tested", noise_threshold="",
              series_vs_exact="", headline="not fitted: no law compared applies")
    fitted = Answer(group="impact", datasets=("impact-x",), best="wear [exact]", **{**kw, "fits": True,
                                                                                    "headline": "best: wear [exact]"})
    none = [Answer(group=g, datasets=(), best=None, **kw) for g in ("slider-a", "slider-b")]
    md = markdown("t", _first(attrs.evolve(comp, answers=(fitted, *none)))[0])
    assert "Not fitted (no law compared applies): slider-a, slider-b." in md
    hint = "rate-state-aging, rate-state-slip (--laws rate-state-aging,rate-state-slip)"
    none = [attrs.evolve(a, headline=f"not fitted: none applies; registered laws that apply: {hint}",
                         short={"best": "not fitted: no law compared applies"}) for a in none]
    md = markdown("t", _first(attrs.evolve(comp, answers=(fitted, *none)))[0])
    assert f"Not fitted (no law compared applies): slider-a, slider-b; registered laws that apply: {hint}." in md
    assert not [line for line in md.splitlines() if line.startswith("| **slider")]


def test_the_golf_story_only_where_the_data_spin_falls(comp):
    """The synthetic wear impact's spin rises throughout contact: the first screen shows the data with the top
    candidates and says so with numbers from the data; the paper's golf data (spin falls) get the story."""
    from frictionlab.core.display import unit
    from frictionlab.report.text import sig

    md = markdown("t", _first(comp)[0])
    assert "paper" not in md and "**What the data show.**" in md
    d = comp.fitted_datasets[0]
    target = comp.fits_on(d.name)[0].per_dataset[0].target
    assert target.observable == "omega"
    name, f = unit("omega")
    assert f"to {sig(float(target.y[-1]) * f)} {name} over 500 µs and never falls" in md
    assert "Ranked first: " in md
    golf = compare(laws=["wear"], datasets=["impact-golf-v28"], equivalence=False, transfer=False)
    md = markdown("t", _first(golf)[0])
    assert "**Why the paper's spin falls.**" in md and "What the data show" not in md
    # the same numbers declared as a user's own: the first screen speaks of no paper
    mine = attrs.evolve(golf.datasets[0], name="ball-golf", provenance=attrs.evolve(
        golf.datasets[0].provenance, kind="measured", source="my lab, 2024"))
    own = compare(laws=["wear"], datasets=[mine], equivalence=False, transfer=False)
    md = markdown("t", _first(own)[0])
    assert "paper" not in md.lower() and "**What the data show.**" in md and "cross zero at 289" in md


def test_cells_are_the_short_forms_and_the_full_sentences_follow_the_table(comp):
    long_goodness = "runs p = 8.1e-10, lag-1 r = +0.94; p Bonferroni-adjusted over 2 datasets; sigma assumed, profiled"
    a = Answer(group="impact-golf", datasets=("impact-golf-v28", "impact-golf-v61"), provenance="reconstructed",
               best="wear = couette [series]", fits=False,
               headline="no registered law describes these data (best of a poor set: wear = couette [series])",
               goodness=long_goodness, equivalence="different", noise_threshold="wear and area-rate differ by "
               "more than the noise when sigma < 1.82 deg on impact-golf-v28 (sigma 0.5 deg)",
               series_vs_exact="impact-golf-v28: the series slip crosses zero at 338 us (b = 0.81)", transfer="",
               equivalence_series="different",
               short={"best": "no law fits (best of a poor set: wear = couette [series])",
                      "goodness": "fails: runs p = 8e-10", "equivalence": "different (exact and series)",
                      "threshold": "differ unless σ > 1.8 deg (σ = 0.5 deg)",
                      "series": "series slip u = 0 at 338 µs; exact never"})
    sections, _ = _first(attrs.evolve(comp, answers=(a,)))
    (table,) = [b for kind, b in sections[0].blocks if kind == "table"]
    (row,) = table.rows
    assert row[1:6] == [a.short[k] for k in ("best", "goodness", "equivalence", "threshold", "series")]
    assert all(len(cell) <= 60 for cell in row)  # a few words per cell, not a sentence
    (notes,) = [b for kind, b in sections[0].blocks if kind == "more"]
    assert [kind for kind, _ in sections[0].blocks].index("more") == [k for k, _ in sections[0].blocks].index("table") + 1
    (note,) = notes[1]
    for text in (a.headline, long_goodness, a.noise_threshold, a.series_vs_exact, "impact-golf-v61"):
        assert sentence(text).rstrip(".") in note
    html = html_page("t", sections, {"finding.png": b""})
    assert '<details class="more">' in html and sentence(long_goodness).rstrip(".") in html
    md = markdown("t", sections)
    assert "fails: runs p = 8e-10" in md and sentence(long_goodness).rstrip(".") in md


def test_the_verdict_layer_fills_the_first_screen(comp):
    md = markdown("t", _first(comp)[0])
    assert "`Comparison.answers` is empty" not in md
    (a,) = comp.answers
    assert sentence(a.headline).rstrip(".") in md.replace("\\", "") and a.goodness.split(" (")[0] in md


def test_names_and_descriptions_never_leak_raw_html(comp, tmp_path):
    sections, _ = build(comp)
    md = markdown("t", sections)
    page = html_page("t", sections, {f.name: b"png" for s in sections for f in s.figures})
    for text in (md, page):
        assert "<script>alert" not in text and "<b>bold</b>" not in text and "<i>raw</i>" not in text
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in md and "impact-&lt;b&gt;bold&lt;/b&gt;" in page


def test_one_functional_form_is_one_entry():
    from frictionlab.report import figures, ranking

    ds = synthetic("wear", {"lam": 1.2e6}, seed=8, n=21, name="impact-forms")
    c = compare(laws=["wear", "couette", "coulomb"], datasets=[ds], solvers=["exact"], equivalence=False)
    curves = figures.distinct_curves(c.fits_on("impact-forms"))
    assert sorted(tuple(sorted(laws)) for _, laws in curves) == [("couette", "wear"), ("coulomb",)]
    md = markdown("t", build(c, modules=[ranking])[0])
    rows = [line for line in md.splitlines() if line.startswith("| 1 |") or line.startswith("| 2 |")]
    # the ranking merges one closed-form family into one candidate (ranking.merge_identical)
    assert len(rows) == 2 and "wear = couette [exact]" in rows[0] and "| 1.000 |" in rows[0]
    assert ranking.law_aliases(c) == {"couette": "wear = couette", "wear": "wear = couette"}  # as the ranking spells it


def test_table_numbers_keep_their_significant_figures():
    from frictionlab.core.display import fmt

    assert [fmt(x) for x in (1.0, 0.5, 12.5, 1100.0, 10090.4, 3.41391)] == ["1.000", "0.5000", "12.50", "1100",
                                                                            "10090", "3.414"]
    assert fmt(-5.349e11) == "-5.349e+11" and fmt(1e-4, 3) == "1.00e-04"


def test_a_parameter_far_from_its_bounds_is_not_at_a_bound():
    """lam = 1655 +/- 84 Pa s/m in [0, 1e13] is 20 standard errors from 0: no bound warning; lam pressed to 0 is."""
    from frictionlab import fit

    weak = synthetic("wear", {"lam": 1655.0}, seed=4, n=26, rel_noise=0.003, name="weak")
    f = fit("wear", weak, solver="exact")
    assert f.ok and f.value("lam") > 10 * f.stderr("lam")
    assert f.identifiability.at_bounds == () and not any("bound" in w for w in f.identifiability.warnings)
    none = synthetic("coulomb", {"mu": 0.2}, seed=4, n=26, name="backwards")
    none = attrs.evolve(none, columns={**none.columns, "omega": -np.abs(none.columns["omega"])})
    g = fit("wear", none, solver="exact")
    assert "lam" in g.identifiability.at_bounds


def test_plausibility_flags_reach_the_parameter_they_name():
    from frictionlab.report.fits import flags_on

    class F:
        flags = ("eta_prime = -7.9e11 N s/m^2 can be set to 0 changing chi2 by 0.3", "slip exceeds 10x u0")

    assert flags_on(F(), "eta_prime") == [F.flags[0]] and flags_on(F(), "eta") == [] and flags_on(F(), "u0") == [
        F.flags[1]]


def test_a_group_row_shows_its_first_flag_and_counts_the_others():
    from frictionlab.inference.verdicts.ranking import RankRow
    from frictionlab.report.ranking import group_table

    row = RankRow("ALL", "area-rate", "exact", 650, 16, aic=1.0, rank=3,
                  flags=("a: rests on eta_prime", "b: slip reaches 10.9 u0", "c: rests on eta_prime"))
    (cells,) = group_table([row])[1]
    assert cells[-1].endswith("; FLAG (ranked after every unflagged candidate that fits): a: rests on eta_prime; 2 more flags: "
                              "see each dataset's table")


def test_the_command_lines_closing_answers_fold_groups_without_a_fitted_law(comp):
    from frictionlab.commands.compare import answer_lines

    kw = dict(provenance="synthetic", fits=False, goodness="", equivalence="not tested", noise_threshold="",
              series_vs_exact="", headline="not fitted: no law compared applies")
    none = [Answer(group=g, datasets=(), best=None, **kw) for g in ("slider-a", "slider-b")]
    fitted = Answer(group="impact", datasets=("impact-x",), best="wear [exact]", **{**kw, "headline": "best: wear"})
    lines = answer_lines(attrs.evolve(comp, answers=(none[0], fitted, none[1])))
    assert lines[1].startswith("  impact: ") and lines[2:] == ["  slider-a, slider-b: not fitted: no law compared applies"]
    hinted = attrs.evolve(none[0], headline="not fitted: none; registered laws that apply: rate-state-slip (--laws "
                          "rate-state-slip)", short={"best": "not fitted: no law compared applies"})
    lines = answer_lines(attrs.evolve(comp, answers=(fitted, hinted)))
    assert lines[2:] == ["  slider-a: not fitted: no law compared applies; registered laws that apply: rate-state-slip "
                         "(--laws rate-state-slip)"]


def test_a_candidate_under_a_higher_ranked_one_is_named_in_its_legend_not_drawn():
    from types import SimpleNamespace as NS

    import numpy as np

    from frictionlab.report.figures.finding import _merged

    fit = lambda y: NS(per_dataset=[NS(model=np.asarray(y, float))])  # noqa: E731
    curves = [(fit([0, 50, 100]), "#1 area-rate [exact]", {}), (fit([0, 30, 90]), "#2 wear [series], ΔAIC 9.0", {}),
              (fit([0, 30.5, 90.4]), "#3 wear [exact], ΔAIC 9.4", {})]
    out = _merged(curves, span=100.0)  # #3 is within 1.5% of the span of #2 everywhere; #2 is 20% off #1
    assert [label for _, label, _ in out] == ["#1 area-rate [exact]", "#2 wear [series], ΔAIC 9.0 (hides #3 wear [exact])"]
    assert len(_merged(curves, span=10.0)) == 3  # on a tenth of the span they are told apart


def test_a_plain_number_is_quoted_without_a_unit_dash_in_the_data_sentence():
    from types import SimpleNamespace as NS

    import numpy as np

    from frictionlab.report.data_view import _shape

    t = np.linspace(0.0, 30.0, 31)
    y = np.where(t < 10, 0.601, 0.593)
    y[10] = 0.615
    target = NS(observable="mu", y=y, t=t, sigma=np.full(31, 5e-4))
    text = _shape(NS(fits=[NS(per_dataset=[NS(target=target)])], dataset=NS(name="block-b")))
    assert "goes from 0.601 to 0.593 over 30 s, peaking at 0.615 at 10 s" in text and " - " not in text


def test_a_spring_slider_report_has_its_fit_figure_and_no_force_figure(tmp_path):
    """A slider's friction is mu N, which the fit figure already shows (a force axis from 0 hid the step)."""
    from frictionlab import compare
    from frictionlab.io.template import template
    from frictionlab.report import write_report

    toml, csv = template("spring-slider", "slider")
    (tmp_path / "slider.toml").write_text(toml)
    (tmp_path / "slider.csv").write_text(csv)
    c = compare(laws=["rate-state-aging"], datasets=[str(tmp_path / "slider.toml")], equivalence=False,
                transfer=False)
    names = {p.name for p in (write_report(c, tmp_path / "rep") / "figures").iterdir()}
    assert "fit-slider.png" in names and "force-slider.png" not in names
