"""Work-precision: measurement rows, the written folder (whole or nothing), the command's errors."""
import csv
import math

import pytest

from frictionlab.cli import main
from frictionlab.pipeline import bench


@pytest.fixture()
def tiny(monkeypatch):
    """A fast configuration: two tolerances, one repeat, short timing loops, small batches."""
    monkeypatch.setattr(bench, "QUICK_RTOLS", (1e-3, 1e-6))
    monkeypatch.setattr(bench, "ODE_METHODS", ("RK45",))
    monkeypatch.setattr(bench, "BATCH_METHODS", ("DOP853",))
    monkeypatch.setattr(bench, "MIN_LOOP", 0.0)
    monkeypatch.setattr(bench, "CHECK_RTOL", 1e-8)
    monkeypatch.setattr(bench, "FIT_CASES", (("incline-oil-a100", ("couette", "coulomb")),))
    monkeypatch.setattr(bench, "QUICK_FIT_RTOLS", (1e-4,))
    real = bench.measure_case

    def fast(name, law, params, scene, rtols, repeats, batch_size, n_t=201, progress=None):
        return real(name, law, params, scene, rtols, 1, 2, n_t=21, progress=progress)

    monkeypatch.setattr(bench, "measure_case", fast)


def test_environment_states_hardware_and_versions():
    env = bench.environment()
    assert env["cpu"] and env["cores"] >= 1
    assert {"python", "numpy", "scipy"} <= set(env["versions"])


def test_measure_case_errors_shrink_with_tolerance(tiny):
    title, law, params, scene = bench.cases()["impact-paper"]
    rows, meta = bench.measure_case("impact-paper", law, params, scene, (1e-3, 1e-8), 1, 3, n_t=41)
    assert meta["reference"].startswith("exact")
    by = {(r["method"], r["rtol"]): r for r in rows}
    assert by[("exact", None)]["error"] < 1e-14
    assert by[("series", None)]["error"] > 0.1  # b = 0.81: the truncated series is far off
    for m in ("ode:RK45", "batch:DOP853"):
        assert by[(m, 1e-8)]["error"] < by[(m, 1e-3)]["error"] < 1e-2
    assert all(r["status"] == "ok" and r["time_median_s"] > 0 for r in rows)


def test_reference_without_closed_form_is_a_tight_integration(monkeypatch):
    monkeypatch.setattr(bench, "CHECK_RTOL", 1e-10)
    title, law, params, scene = bench.cases()["incline-dry"]
    import numpy as np

    ref, name, check = bench.reference(law, params, scene, np.linspace(0, scene.duration, 21))
    assert "1e-13" in name and check < 1e-9


def test_bench_command_writes_whole_folder(tiny, tmp_path, capsys):
    out = tmp_path / "wp"
    assert main(["bench", "--out", str(out), "--quick"]) == 0
    names = {p.name for p in out.iterdir()}
    assert {"workprecision.csv", "workprecision.md", "environment.json"} <= names
    assert {f"workprecision_{k}.png" for k in bench.cases()} <= names
    rows = list(csv.DictReader(open(out / "workprecision.csv")))
    assert {r["case"] for r in rows} == set(bench.cases())
    assert any(r["method"] == "batch:DOP853" for r in rows)
    assert all(math.isfinite(float(r["time_median_s"])) for r in rows if r["status"] == "ok")
    md = (out / "workprecision.md").read_text()
    assert "Hardware:" in md and "numpy" in md and "What the tolerance does to a fit" in md
    fits = list(csv.DictReader(open(out / "fit_tolerance.csv")))
    assert {r["solver"] for r in fits} == {"exact", "ode:LSODA"} and {r["law"] for r in fits} == {"couette", "coulomb"}
    assert all(r["ranking_as_reference"] == "True" for r in fits)
    # existing folder: refused before measuring, one line, exit 2
    assert main(["bench", "--out", str(out), "--quick"]) == 2
    assert "exists" in capsys.readouterr().err


def test_failed_run_leaves_no_folder(tiny, tmp_path, monkeypatch):
    out = tmp_path / "wp"
    one = {"impact-paper": bench.cases()["impact-paper"]}
    monkeypatch.setattr(bench, "cases", lambda: one)

    def boom(*a, **k):
        raise bench.FrictionLabError("disk full")

    from frictionlab.pipeline import benchplot

    monkeypatch.setattr(benchplot, "plot_case", boom)
    assert main(["bench", "--out", str(out), "--quick", "--no-fits"]) == 2
    assert not out.exists() and not list(tmp_path.iterdir())


def test_fit_tolerance_study_rows():
    from frictionlab.inference.cost.tolerance import fit_tolerance_study, markdown

    rows = fit_tolerance_study(["couette"], "incline-oil-a100", methods=("LSODA",), rtols=(1e-3, 1e-8))
    assert [r["solver"] for r in rows] == ["exact", "ode:LSODA", "ode:LSODA"]
    assert rows[0]["shift_in_stderr"] == 0.0 and abs(rows[2]["shift_in_stderr"]) < 1e-2
    assert all(r["fit_time_s"] > 0 and r["rank"] == 1 for r in rows)
    assert "| couette | exact |" in markdown(rows)
    import importlib

    assert importlib.import_module("frictionlab.inference.fitting.predict").FIT_RTOL == 1e-6  # restored after the study


def test_tied_laws_share_a_place_in_the_tolerance_study():
    from frictionlab.inference.cost.tolerance import fit_tolerance_study

    rows = fit_tolerance_study(["couette", "wear"], "incline-oil-a100", methods=("LSODA",), rtols=(1e-8,))
    assert all(r["rank"] == 1 and r["ranking"] == "wear = couette" and r["ranking_as_reference"] for r in rows)


def test_fit_takes_its_tolerance_as_an_argument():
    """rtol=None is the default FIT_RTOL exactly; a loose rtol changes the ODE fit; a bad one is one line."""
    from frictionlab import fit
    from frictionlab.core.errors import ParameterError
    from frictionlab.inference.fitting.predict import FIT_RTOL

    default = fit("wear", "incline-oil-a100", solver="ode", scan=0)
    explicit = fit("wear", "incline-oil-a100", solver="ode", scan=0, rtol=FIT_RTOL)
    loose = fit("wear", "incline-oil-a100", solver="ode", scan=0, rtol=1e-3)
    assert default.value("lam") == explicit.value("lam") != loose.value("lam")
    assert default.cpu_time > 0
    for bad in (0.0, 1.5, "1e-3", True):
        with pytest.raises(ParameterError, match="rtol"):
            fit("wear", "incline-oil-a100", solver="ode", rtol=bad)


def test_tolerance_study_on_threads_matches_serial():
    """No module state is patched: fits at different tolerances can run side by side."""
    from concurrent.futures import ThreadPoolExecutor

    from frictionlab.inference.cost.tolerance import fit_tolerance_study

    args = (["wear"], "incline-oil-a100", ("LSODA",), (1e-3, 1e-6))
    serial = fit_tolerance_study(*args)
    with ThreadPoolExecutor(3) as ex:
        threaded = fit_tolerance_study(*args, executor=ex)
    assert [(r["rtol"], r["value"], r["stderr"]) for r in serial] == [(r["rtol"], r["value"], r["stderr"])
                                                                        for r in threaded]
    assert serial[1]["value"] != serial[2]["value"]  # the tolerances really differ


def test_log_axes_label_their_ticks_in_plain_text_with_mathtext_off():
    """pyplot() turns mathtext off; matplotlib's default log labels are mathtext and would print as TeX."""
    from frictionlab.core.display import plain_log, pyplot

    plt = pyplot()
    fig, ax = plt.subplots()
    ax.plot([1e-6, 1e-2], [5e-6, 9e-6])
    ax.set_xscale("log")
    ax.set_yscale("log")
    plain_log(ax.xaxis)
    plain_log(ax.yaxis)
    fig.canvas.draw()
    labels = [t.get_text() for t in ax.get_xticklabels() + ax.get_yticklabels(which="both") if t.get_text()]
    plt.close(fig)
    assert labels and not [x for x in labels if "$" in x or "mathdefault" in x]
    assert "1e-04" in [x.replace("\u2212", "-") for x in labels]  # matplotlib writes a true minus sign
