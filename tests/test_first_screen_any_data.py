"""A first screen for any data: the paper is named only for the paper's data (by provenance), the figure draws
each group's top-ranked candidates (the slip of the truncated series only where it is one of them), what
accuracy costs is answered for every law and dataset, and kinds with a block of their own plug in at one place."""
import math
from pathlib import Path

import attrs
import pytest

from frictionlab import compare, load_dataset
from frictionlab.inference.cost.accuracy import BUDGET, COMMAND, RTOLS, solver_costs, study_fits
from frictionlab.io.template import template
from frictionlab.report import build, first_screen
from frictionlab.report.data_view import group_views
from frictionlab.report.render import markdown

KT = Path(__file__).resolve().parent.parent / "examples" / "known-truth"


def test_the_paper_is_the_papers_by_its_declared_source_not_its_name(tmp_path):
    for name in ("impact-golf-v28", "impact-golf-v61", "impact-area-v32"):
        assert load_dataset(name).provenance.seed_paper, name
    for name in ("incline-oil-a100", "kharaz2001-spin", "impact-outcome-synthetic"):
        assert not load_dataset(name).provenance.seed_paper, name
    assert not load_dataset(KT / "kt-wear-impact.toml").provenance.seed_paper
    toml, csv = template("impact", "impact-golf-mine")  # a paper-like name, a user's source
    (tmp_path / "impact-golf-mine.toml").write_text(toml)
    (tmp_path / "impact-golf-mine.csv").write_text(csv)
    assert not load_dataset(tmp_path / "impact-golf-mine.toml").provenance.seed_paper


@pytest.fixture(scope="module")
def users_impact(tmp_path_factory):
    """A user's own impact: the template's scene, own numbers (a spin that rises and saturates, no law of
    frictionlab), no [noise] table, measured provenance."""
    import numpy as np

    folder = tmp_path_factory.mktemp("user")
    toml, _ = template("impact", "ball-a")
    start = toml.index("[noise]")
    toml = toml[:start] + toml[toml.index("\n\n", start) + 2:]
    toml = toml.replace('kind = "synthetic"\nsource = "frictionlab datasets template: example numbers, not a '
                        'measurement; replace with your source"', 'kind = "measured"\nsource = "my lab, 2024"')
    (folder / "ball-a.toml").write_text(toml)
    t = np.linspace(0.0, 500.0, 21)
    w = 5200 * (1 - np.exp(-t / 140.0)) + 20 * np.sin(7.1 * np.arange(21))
    th = np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * 6 * np.diff(t) * 1e-6)])  # deg
    (folder / "ball-a.csv").write_text("t,omega,theta\n" + "".join(f"{a:g},{b:.2f},{c:.4f}\n" for a, b, c in zip(t, w, th)))
    return compare(datasets=[folder / "ball-a.toml"], replicates=20)


def test_a_users_impact_first_screen_names_neither_the_paper_nor_a_law_it_did_not_rank_first(users_impact):
    c = users_impact
    (d,) = c.datasets
    assert d.noise_kind == "estimated" and not d.provenance.seed_paper
    sections, _ = build(c, modules=[first_screen])
    md = markdown("t", sections)
    assert "paper" not in md.lower()
    first = {r.law for r in c.ranking if r.rank == 1}
    (view,) = group_views(c, first_screen.series_findings(c))
    assert {f.law for f in view.fits} <= first | {m for r in c.ranking if r.rank == 1 for m in r.members}
    laws = {r.law for r in c.ranking if r.rank is not None} - first
    figure = next(b for kind, b in sections[0].blocks if kind == "fig")
    said = " ".join(view.labels) + figure.caption + next(b for kind, b in sections[0].blocks
                                                         if kind == "p" and b.startswith("**What the data show"))
    for law in laws:
        assert f"{law} [" not in said, law
    if view.series is None:
        assert "slip" not in figure.caption


def test_what_accuracy_costs_is_answered_for_every_law_and_dataset(users_impact):
    c = users_impact
    fitted = {(f.datasets[0], f.law) for f in c.fits if f.ok}
    assert {(r.dataset, r.law) for r in c.accuracy} == fitted
    for r in c.accuracy:
        assert r.status == "ok", r
    wear = {r.label: r for r in c.accuracy if r.law == "wear"}
    assert wear["exact"].reference and wear["exact"].error == 0 and wear["exact"].time_ratio == 1
    assert {"series", *(f"ode rtol {x:.0e}".replace("e-0", "e-") for x in RTOLS)} <= set(wear)
    # the ODE converges on the closed form as its tolerance tightens; the series does not
    ode = [wear[f"ode rtol {x:.0e}".replace("e-0", "e-")].error for x in RTOLS]
    assert ode[0] > ode[1] > ode[2] and wear["series"].error > ode[1]
    (a,) = c.answers
    assert a.short["accuracy"].startswith("vs exact: series ≤ ") and "σ at" in a.short["accuracy"]
    assert a.accuracy.startswith("Against the closed form") and "the fits' own tolerance" in a.accuracy
    md = markdown("t", build(c, modules=[first_screen])[0])
    assert "what accuracy costs" in md and "What accuracy costs, per law and dataset" in md
    assert c.timings["accuracy"] < 30  # cheap: a few predictions per law and dataset


def test_where_it_is_not_cheap_it_says_how_to_run_it(users_impact, monkeypatch):
    from frictionlab.inference.cost import accuracy

    f = next(f for f in users_impact.fits if f.ok and f.solver == "exact")
    slow = attrs.evolve(f, cpu_time=BUDGET * f.nfev)  # as if one evaluation took BUDGET seconds
    monkeypatch.setattr(accuracy, "BUDGET", 1e-12)  # and a timed prediction also costs more than the budget
    (row,) = solver_costs(slow)
    assert row.status == "not run" and COMMAND in row.reason and "CPU s" in row.reason
    assert solver_costs(slow, full=True)[0].reference  # the full study runs it anyway


def test_a_fit_slowed_by_a_one_time_cost_still_gets_its_study(users_impact):
    """A fit's CPU time may hold a kernel compiled once per machine (a fresh install's first fit): where the fit's
    time per evaluation says the study is dear, one timed prediction decides."""
    f = next(f for f in users_impact.fits if f.ok and f.solver == "exact")
    slow = attrs.evolve(f, cpu_time=BUDGET * f.nfev)  # as if one evaluation took BUDGET seconds
    rows = solver_costs(slow)
    assert rows[0].reference and rows[0].status == "ok" and len(rows) > 1
    assert len(study_fits(users_impact.fits)) == len({(g.datasets[0], g.law) for g in users_impact.fits if g.ok})


def test_a_kind_with_a_block_of_its_own_plugs_in_at_one_place(users_impact, monkeypatch):
    called = []

    def block(ctx, sec, datasets):
        called.append([d.name for d in datasets])
        sec.p("A block of its own for impacts.")

    monkeypatch.setitem(first_screen.KIND_BLOCKS, "impact", block)
    sections, _ = build(users_impact, modules=[first_screen])
    assert called == [["ball-a"]]
    md = markdown("t", sections)
    assert "A block of its own for impacts." in md and "finding.png" not in md  # left out of the generic figure


def test_the_builtin_first_screen_draws_each_groups_top_ranked_candidates():
    c = compare(laws=["wear", "area-rate"], datasets=["impact-golf-v28", "impact-golf-v61", "incline-oil-a100"],
                equivalence=False, transfer=False)
    views = group_views(c, first_screen.series_findings(c))
    assert [v.group for v in views] == ["impact-golf", "incline-oil"]  # declared groups, one member here
    golf, oil = views
    top = {(r.law, r.solver) for r in c.groups if r.dataset == "impact-golf" and r.rank == 1}
    assert {(f.law, f.solver) for f in golf.fits} <= {(m, s) for law, s in top for m in law.split(" = ")}
    assert golf.series is not None and golf.series.t_cross is not None  # the series is top-ranked: its slip shown
    assert oil.series is None and all(f.solver != "series" for f in oil.fits)
    md = markdown("t", build(c, modules=[first_screen])[0])
    assert "**Why the paper's spin falls.**" in md  # the paper's data, whose spin falls


def test_margin_and_family_are_options_of_the_command_and_the_library(tmp_path):
    from frictionlab.cli import main
    from frictionlab.core.errors import ParameterError

    c = compare(laws=["wear", "couette"], datasets=[KT / "kt-wear-impact.toml"], margin=0.5, family="group",
                transfer=False, replicates=20)
    (e,) = c.equivalence
    assert e.margin_text.startswith("δ = 0.5 × σ") and e.verdict == "equivalent within δ"
    assert c.settings["margin"] == "0.5 × σ" and c.settings["family"] == "group"
    with pytest.raises(ParameterError, match="margin '3 m/s' is not a quantity of kt-wear-impact's observable omega"):
        compare(laws=["wear"], datasets=[KT / "kt-wear-impact.toml"], margin="3 m/s")
    with pytest.raises(ParameterError, match="cannot apply to impact-golf-v28"):
        compare(laws=["wear"], datasets=["impact-golf-v28"], margin="100 rpm")
    out = tmp_path / "rep"
    code = main(["compare", "--laws", "wear,couette", "--data", str(KT / "kt-wear-impact.toml"), "--margin", "200 rpm",
                 "--replicates", "20", "--bootstrap", "0", "--out", str(out), "-q"])
    assert code == 0
    text = (out / "report.md").read_text()
    assert "δ = 200 rpm, the margin asked for" in text
    assert main(["compare", "--data", "impact-golf-v28", "--margin", "100 rpm", "--out", str(tmp_path / "x"),
                 "-q"]) == 2 and not (tmp_path / "x").exists()
    assert not math.isnan(e.p_within)


def test_a_comparison_of_many_groups_draws_the_first_of_them_and_says_so(monkeypatch):
    """The first screen's figure and the ranking heat map have a bounded size: past MAX_PANELS groups (MAX_COLUMNS
    datasets) they draw the first ones and their captions say how many of how many, and where the rest are."""
    from frictionlab.report import ranking as ranking_section

    c = compare(laws=["wear", "area-rate"], datasets=["impact-golf-v28", "impact-golf-v61", "incline-oil-a100"],
                equivalence=False, transfer=False, bootstrap=0)
    drawn = {}
    monkeypatch.setattr(first_screen, "MAX_PANELS", 1)
    monkeypatch.setattr(ranking_section, "MAX_COLUMNS", 2)
    monkeypatch.setattr(first_screen.figures, "group_figure", lambda views, title: drawn.setdefault("views", views))
    monkeypatch.setattr(ranking_section.figures, "ranking_figure", lambda rows, alias: drawn.setdefault("rows", rows))
    sections = build(c, modules=[first_screen, ranking_section])[0]
    md = markdown("t", sections)
    for s in sections:
        for f in s.figures:
            f.draw()
    assert [v.group for v in drawn["views"]] == ["impact-golf"]
    assert {r.dataset for r in drawn["rows"]} == {"impact-golf-v28", "impact-golf-v61"}
    assert "The first 1 of 2 groups; each group's page (under 'Dataset groups') draws its own." in md
    assert "The first 2 of 3 datasets; the tables below and ranking.csv hold every one." in md
    assert "### incline-oil-a100" in md.split("The first 2 of 3 datasets")[-1]  # the ranking's tables: every dataset


def test_each_kind_of_solver_is_warmed_once_before_it_is_timed(users_impact, monkeypatch):
    """The reference, the series and the first ODE tolerance get one untimed call first (a kernel compiled, a
    cache filled); a later ODE tolerance shares the first one's, so its first call is timed."""
    from frictionlab.inference.cost import accuracy

    warmed = []
    real = accuracy._timed
    monkeypatch.setattr(accuracy, "_timed", lambda law, tg, p, solver, scene, rtol, warm=False: (
        warmed.append((solver, rtol, warm)), real(law, tg, p, solver, scene, rtol, warm))[1])
    f = next(f for f in users_impact.fits if f.ok and f.law == "wear" and f.solver == "exact")
    rows = solver_costs(f, full=True)
    assert [(s, w) for s, _, w in warmed] == [("exact", False), ("series", False), ("ode", False), ("ode", True),
                                              ("ode", True)]
    assert [r for _, r, _ in warmed if r is not None] == list(RTOLS)
    assert all(r.status == "ok" and r.time_s > 0 for r in rows)
