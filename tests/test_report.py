"""The report folder: contents, self-contained HTML, schema, atomic writing, and the commands."""
import csv
import io
import json
import re
from pathlib import Path

import numpy as np
import pytest
from _fit_helpers import TRUTH, synthetic

from frictionlab import compare, write_report
from frictionlab.cli import main
from frictionlab.core.errors import FrictionLabError, OutputError
from frictionlab.core.outfolder import MARKER
from frictionlab.core.progress import Progress
from frictionlab.inference.verdicts.ranking import COLUMNS


@pytest.fixture(scope="module")
def comparison():
    ds = synthetic("area-rate", TRUTH["area-rate"], seed=11, name="synth-impact")
    return compare(laws=["wear", "area-rate"], datasets=[ds])


@pytest.fixture(scope="module")
def report_dir(comparison, tmp_path_factory):
    return write_report(comparison, tmp_path_factory.mktemp("report") / "rep")


def test_report_folder_contents(report_dir):
    out = report_dir
    names = {p.name for p in out.iterdir()}
    assert {"report.md", "report.html", "ranking.csv", "results.json", "figures"} <= names
    pngs = sorted((out / "figures").glob("*.png"))
    assert {p.name for p in pngs} >= {"fit-synth-impact.png", "force-synth-impact.png",
                                      "equivalence-synth-impact.png", "derive-synth-impact.png"}
    assert "ranking.png" not in {p.name for p in pngs}  # of one dataset: its candidate table says it all
    assert all(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in pngs)
    md = (out / "report.md").read_text()
    for p in pngs:
        assert f"figures/{p.name}" in md
    assert "SYNTHETIC" in md and "not measured" in md  # never presented as measured
    assert "1/(φA0)" in md and "φ/A0" in md  # the paper's misprinted factor is named
    assert "equivalent" in md
    # the generating law and parameters are checked in the report itself
    assert "**Known truth:** generated with area-rate. area-rate [exact] ranks #1" in md
    assert "eta_prime: true 8000 N s/m^2, fitted" in md


def test_html_is_self_contained(report_dir):
    out = report_dir
    html = (out / "report.html").read_text()
    n_figs = len(list((out / "figures").glob("*.png")))
    assert html.count("data:image/png;base64,") == n_figs
    assert "src='figures/" not in html and 'src="figures/' not in html and "<link" not in html
    assert "<script src" not in html and html.count("<script>") == 1  # the inline table sorter only
    assert '<table class="sortable' in html


def test_ranking_csv_and_results_json(report_dir):
    out = report_dir
    rows = list(csv.DictReader(io.StringIO((out / "ranking.csv").read_text())))
    assert list(rows[0]) == list(COLUMNS) + ["observable", "rss_unit", "rmse_unit"]
    assert {(r["observable"], r["rss_unit"], r["rmse_unit"]) for r in rows if r["dataset"] == "synth-impact"} == {
        ("omega", "(rad/s)^2", "rad/s")}
    per = [r for r in rows if r["dataset"] == "synth-impact"]
    assert {(r["law"], r["solver"]) for r in per} == {("wear", "exact"), ("wear", "series"), ("area-rate", "exact")}
    best = [r for r in per if r["rank"] == "1"]
    assert [r["law"] for r in best] == ["area-rate"]
    weighted = [r for r in per if r["akaike_weight"]]  # weights compare the candidates that fit, and only those
    assert weighted and sum(float(r["akaike_weight"]) for r in weighted) == pytest.approx(1.0)
    assert all(r["fits"] != "False" for r in weighted) and all(r["weight_among"] for r in weighted)
    assert not any(r["dataset"].startswith("ALL") for r in rows)  # no group sums datasets nobody declared together

    data = json.loads((out / "results.json").read_text())
    assert data["schema"] == "frictionlab.compare/1"
    assert {"numpy", "scipy", "lmfit", "frictionlab"} <= set(data["versions"])
    assert data["datasets"][0]["provenance"]["kind"] == "synthetic"
    fit = next(f for f in data["fits"] if f["law"] == "area-rate")
    assert set(fit["parameters"]) == {"mu", "eta_prime"}
    mu = fit["parameters"]["mu"]
    assert abs(mu["value"] - TRUTH["area-rate"]["mu"]) < 3 * mu["stderr"]
    assert {"aic", "aicc", "bic", "redchi", "chisqr", "rss", "rmse"} <= set(fit["statistics"])
    assert fit["statistics"]["observable_unit"] == "rad/s"
    assert "verdict" in fit["identifiability"]
    eq = data["equivalence"]
    assert {(e["law_a"], e["solver_a"], e["law_b"]) for e in eq} == {("wear", "exact", "area-rate"),
                                                                   ("wear", "series", "area-rate")}
    assert all(e["verdict"] and e["explanation"] and len(e["t_a"]) >= 10 for e in eq)
    assert [e["solver_a"] for e in eq if e["decomposition"]] == ["series"]  # never for the exact solution
    assert "poly9" in data["derivations"]["synth-impact"]


def _small_pair():
    """A synthetic impact (closed forms) and every 4th row of a dry incline (wear needs the ODE there)."""
    import attrs

    from frictionlab import load_dataset

    dry = load_dataset("incline-dry-d10")
    dry = attrs.evolve(dry, name="dry-small", columns={k: v[::4] for k, v in dry.columns.items()})
    return [synthetic("wear", TRUTH["wear"], seed=3, n=21, name="impact-small"), dry]


@pytest.fixture(scope="module")
def boot_report(tmp_path_factory):
    """Bootstrap (10 resamples, seed 7, two worker processes) and the tolerance check at 1e-3."""
    c = compare(laws=["wear", "coulomb"], datasets=_small_pair(), equivalence=False, tolerance=(1e-3,), bootstrap=10,
                seed=7, jobs=2)
    out = write_report(c, tmp_path_factory.mktemp("boot") / "rep")
    return (out / "report.md").read_text(), json.loads((out / "results.json").read_text())


def _bootstrap_tables(c) -> str:
    from frictionlab.report import bootstrap, build
    from frictionlab.report.render import markdown

    md = markdown("t", build(c, modules=[bootstrap])[0])
    return md[md.index("### First place under resampling"):]


def test_bootstrap_tables_depend_on_the_seed_only(boot_report):
    md, data = boot_report
    impact = _small_pair()[:1]
    again = compare(laws=["wear", "coulomb"], datasets=impact, equivalence=False, bootstrap=10, seed=7, jobs=1)
    other = compare(laws=["wear", "coulomb"], datasets=impact, equivalence=False, bootstrap=10, seed=8, jobs=1)
    tables = md[md.index("### First place under resampling"):md.index("## Fits")].strip() + "\n"
    assert _bootstrap_tables(again) == tables  # same seed, one worker process or two: the same numbers
    assert _bootstrap_tables(other) != tables
    assert "parametric replicates" in md and "percentile intervals" in md and "Wilson score interval" in md


def test_results_json_carries_the_intervals(boot_report):
    md, data = boot_report
    b = data["bootstrap"]
    assert (b["n"], b["seed"], b["method"], b["interval"], b["first_place_interval"]) == (10, 7, "parametric", "percentile",
                                                                                          "wilson")
    (impact,) = b["datasets"]  # the ODE dataset is left out by default, with the reason and the flag
    assert impact["dataset"] == "impact-small" and impact["n_ranked"] == 10
    assert "--bootstrap-all" in b["not_bootstrapped"]["dry-small"] and "`--bootstrap-all`" in md
    lam = next(r for r in impact["parameters"] if r["law"] == "wear" and r["solver"] == "exact")
    assert lam["parameter"] == "lam" and lam["ci_low"] < lam["value"] < lam["ci_high"] and lam["n_ok"] == 10
    first = {r["candidate"]: r for r in impact["first_place"]}
    assert set(first) == {"wear [exact]", "wear [series]", "coulomb [exact]"}
    assert sum(r["first_count"] for r in first.values()) == pytest.approx(10)
    assert all(0 <= r["ci_low"] <= r["first_fraction"] <= r["ci_high"] <= 1 for r in first.values())


def test_tolerance_table_in_the_report(boot_report):
    md, data = boot_report
    section = md[md.index("## What solver tolerance does to a fit"):md.index("## Identifiability warnings")]
    assert "On **dry-small**" in section and "`frictionlab bench`" in section
    assert "| wear | 1e-6 (default) |" in section and "| wear | 1e-3 |" in section
    assert "coulomb (closed form) keeps its fit" in section
    assert "**Solver tolerance** (dry-small): refitted at rtol 1e-3" in md
    tol = data["tolerance"]
    assert tol["default_rtol"] == 1e-6 and tol["rtols"] == [1e-3]
    assert {(r["law"], r["rtol"]) for r in tol["rows"]} == {("wear", 1e-6), ("wear", 1e-3)}
    assert all(r["fit_time_s"] > 0 for r in tol["rows"])


def test_without_bootstrap_the_report_says_so(report_dir):
    md = (report_dir / "report.md").read_text()
    assert "## Bootstrap: how firm are the parameters and the ranking" in md
    assert "Not run: this comparison was made with `--bootstrap 0`" in md
    assert "### First place under resampling" not in md and "Parameter intervals" not in md
    data = json.loads((report_dir / "results.json").read_text())
    assert data["bootstrap"]["n"] == 0 and data["bootstrap"]["datasets"] == []


def test_existing_folder_is_refused_then_replaced_with_force(comparison, tmp_path):
    out = tmp_path / "rep"
    out.mkdir()
    (out / "keep.txt").write_text("mine")
    with pytest.raises(OutputError, match="exists"):
        write_report(comparison, out)
    assert (out / "keep.txt").read_text() == "mine"
    with pytest.raises(OutputError, match="replaces only a folder written by frictionlab"):
        write_report(comparison, out, force=True)  # not a report: --force does not delete it either
    assert (out / "keep.txt").read_text() == "mine"
    (out / "keep.txt").unlink()
    write_report(comparison, out, force=True)  # an empty folder may be replaced (a report too: test_hardening)
    assert (out / "report.md").exists() and (out / MARKER).is_file()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no .old, .tmp or .lock left


def test_a_failure_while_writing_leaves_nothing_behind(comparison, tmp_path, monkeypatch):
    from frictionlab.report import figures

    def boom(*a, **k):
        raise RuntimeError("figure failed")

    monkeypatch.setattr(figures, "force_figure", boom)
    with pytest.raises(RuntimeError):
        write_report(comparison, tmp_path / "rep")
    assert list(tmp_path.iterdir()) == []


def test_figures_drawn_by_worker_processes_are_the_ones_drawn_here(comparison, report_dir, tmp_path, monkeypatch):
    """write_report(jobs=2) draws the figures on forked workers: the same files, byte for byte; a figure that
    fails there fails the report as it does here, leaving nothing behind."""
    par = write_report(comparison, tmp_path / "par", jobs=2)
    names = sorted(p.name for p in (report_dir / "figures").iterdir())
    assert len(names) > 2 and names == sorted(p.name for p in (par / "figures").iterdir())
    for name in names:
        assert (par / "figures" / name).read_bytes() == (report_dir / "figures" / name).read_bytes(), name
    def html(d):  # the same but for the minute it was written ("Generated 2026-11-23 07:08 UTC by ...")
        return re.sub(r"Generated \d{4}-\d\d-\d\d \d\d:\d\d \S+ by", "Generated <time> by", (d / "report.html").read_text())

    assert "Generated <time> by" in html(par)
    assert html(par) == html(report_dir)
    from frictionlab.report import figures

    monkeypatch.setattr(figures, "force_figure", lambda *a, **k: 1 / 0)
    with pytest.raises(ZeroDivisionError):
        write_report(comparison, tmp_path / "bad", jobs=2)
    assert not (tmp_path / "bad").exists()


def _write_dataset(folder: Path) -> Path:
    ds = synthetic("wear", {"lam": 1.2e6}, seed=4, n=21)
    t = ds.t * 1e6
    rpm = ds.columns["omega"] * 60 / (2 * np.pi)
    lines = ["t,omega"] + [f"{a:.6g},{b:.8g}" for a, b in zip(t, rpm)]
    (folder / "tiny.csv").write_text("\n".join(lines) + "\n")
    sigma = ds.noise["omega"] * 60 / (2 * np.pi)
    (folder / "tiny.toml").write_text(f"""name = "tiny"
kind = "impact"
observable = "omega"
[columns]
t = "us"
omega = "rpm"
[noise]
kind = "known"
omega = "{sigma:.6g} rpm"
[scene]
mass = "46 g"
radius = "21.3 mm"
u0 = "12 m/s"
effects = ["spin"]
[scene.area]
model = "half-sine"
peak = "130 mm^2"
contact_time = "500 us"
[scene.normal]
model = "half-sine"
impulse = "2.0079 N*s"
[provenance]
kind = "synthetic"
source = "tests"
command = "tests/test_report.py"
seed = 4
""")
    return folder / "tiny.toml"


def test_compare_and_fit_commands(tmp_path, capsys):
    toml = _write_dataset(tmp_path)
    out = tmp_path / "rep"
    assert main(["compare", "--laws", "wear,coulomb", "--data", str(toml), "--out", str(out), "--jobs", "1",
                 "--bootstrap", "5", "--seed", "2"]) == 0
    captured = capsys.readouterr()
    assert "report:" in captured.out
    assert re.search(r"compare: fit \d+/\d+ \(\d+%\) .*; (ETA|took) ", captured.err)  # progress lines, not a bar
    assert "\r" not in captured.err and re.search(r"compare: bootstrap 5/5 \(100%\) ", captured.err)
    assert re.search(r"report: \d+/\d+ \(\d+%\) figure ", captured.err)
    assert (out / "report.html").exists()
    assert "first in 100% of 5 resamples" in (out / "report.md").read_text()
    for bad in (["--bootstrap", "-1"], ["--seed", "-3"]):
        assert main(["compare", "--data", str(toml), "--out", str(tmp_path / "y")] + bad) == 2
        assert bad[0] in capsys.readouterr().err
    assert main(["compare", "--laws", "wear", "--data", str(toml), "--out", str(out)]) == 2
    assert "exists" in capsys.readouterr().err
    assert main(["fit", "wear", str(toml), "--free", "u0=8 m/s:14 m/s"]) == 0
    text = capsys.readouterr().out
    assert "lam" in text and "u0" in text
    assert main(["fit", "wear", str(toml), "--free", "u0=8:14"]) == 2
    assert "unit" in capsys.readouterr().err
    assert main(["compare", "--laws", "nope", "--data", str(toml), "--out", str(tmp_path / "x")]) == 2
    assert "unknown law" in capsys.readouterr().err


def test_progress_is_a_bar_on_a_terminal_and_timestamped_lines_otherwise():
    class Tty(io.StringIO):
        def isatty(self):
            return True

    tty, pipe, quiet = Tty(), io.StringIO(), io.StringIO()
    for stream, q in ((tty, False), (pipe, False), (quiet, True)):
        with Progress("compare", stream=stream, quiet=q, every=3600) as bar:
            for k in range(1, 11):
                bar(k, 10, f"wear [exact] on x{k}")
    assert "10/10" in tty.getvalue() and "compare" in tty.getvalue()  # tqdm's bar
    lines = pipe.getvalue().splitlines()
    assert len(lines) == 2  # the first and the last; the others within the 3600 s interval
    assert re.match(r"^\d{4}-\d\d-\d\d \d\d:\d\d:\d\d compare: 1/10 \(10%\) wear \[exact\] on x1; ETA \d+:\d\d:\d\d$",
                    lines[0])
    assert lines[1].endswith("took 0:00:00") and " 10/10 (100%) " in lines[1]
    assert quiet.getvalue() == ""


def test_a_new_dataset_kind_plugs_in_through_one_predictor(tmp_path, monkeypatch):
    """Rows are impacts (no time column): a predictor registered for the kind is all compare and
    the report need; without it the dataset is skipped with the reason."""
    import attrs

    from frictionlab import simulate
    from frictionlab.inference.fitting import fit as fitting
    from frictionlab.io.dataset import Dataset

    base = synthetic("wear", {"lam": 1.2e6})
    speeds = np.array([8.0, 10.0, 12.0, 14.0, 16.0])

    def final_spins(law, scene, params, solver, u0s):
        return np.array([simulate(law, attrs.evolve(scene, u0=u), params, solver=solver,
                                  t=np.array([0.0, scene.duration])).omega[-1] for u in u0s])

    def predict_outcome(law, target, scene, params, solver):
        return final_spins(law, scene, params, solver, target.dataset.columns["speed"])

    truth = final_spins("wear", base.scene, {"lam": 1.2e6}, "exact", speeds)
    rng = np.random.default_rng(2)
    ds = Dataset(name="outcomes", kind="impact-outcome", observable="rebound_spin", path=None,
                 columns={"speed": speeds, "rebound_spin": truth + rng.normal(0, 5.0, speeds.size)},
                 units={"speed": "m/s", "rebound_spin": "rad/s"}, noise={"rebound_spin": 5.0},
                 scene=attrs.evolve(base.scene, kind="impact-outcome"), fixed={}, provenance=base.provenance)
    monkeypatch.delitem(fitting.PREDICTORS, "impact-outcome")
    with pytest.raises(FrictionLabError, match=r"none of the datasets can be fitted: outcomes: no predictor"):
        compare(laws=["wear"], datasets=[ds], equivalence=False)

    monkeypatch.setitem(fitting.PREDICTORS, "impact-outcome", predict_outcome)
    c = compare(laws=["wear", "coulomb"], datasets=[ds])
    f = c.fit_for("outcomes", "wear", "exact")
    assert f.ok and abs(f.value("lam") - 1.2e6) < 3 * f.stderr("lam")
    out = write_report(c, tmp_path / "rep")
    assert (out / "figures" / "fit-outcomes.png").exists()
    assert not (out / "figures" / "force-outcomes.png").exists()  # no time series, no force history


def test_a_long_step_is_not_silent():
    import time as _time

    pipe = io.StringIO()
    with Progress("compare", stream=pipe, every=3600, heartbeat=0.2) as bar:
        bar(1, 3, "first")
        _time.sleep(1.2)  # one long step: heartbeat lines, not silence
    lines = pipe.getvalue().splitlines()
    assert len(lines) >= 2 and all(" compare: 1/3 done, still working (" in x for x in lines[1:])


def test_laws_of_one_closed_form_family_are_one_curve_in_the_figures():
    """Wear and Couette fitted to one dataset are the ranking's one candidate 'wear = couette': the figures draw
    them as one curve under that name, even where their best fits differ by the optimizer's tolerance by more
    than a thousandth of the noise at some point (golf-v28's stated numbers: the legend once named it twice)."""
    from frictionlab import fit
    from frictionlab.report.figures import base

    wear, couette = fit("wear", "impact-golf-v28", solver="exact"), fit("couette", "impact-golf-v28", solver="exact")
    curves = base.distinct_curves([wear, couette])
    assert [laws for _, laws in curves] == [["wear", "couette"]]
    coulomb = fit("coulomb", "impact-golf-v28", solver="exact")
    assert len(base.distinct_curves([wear, coulomb])) == 2
