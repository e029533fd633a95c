"""``frictionlab simulate``: summary, CSV (SI), figure, parameters with units, one-line errors."""
from __future__ import annotations

import math
import shutil

import numpy as np
import pandas as pd
import pytest

import frictionlab as fl
from frictionlab import cli
from frictionlab.io.dataset import builtin_dir
from frictionlab.report.figures import is_png
from frictionlab.solve.outcome import predict_outcomes
from test_bad_inputs import PROGRESS_LINE

RPM = 60 / (2 * math.pi)


def run(capsys, *argv):
    rc = cli.main(list(argv))
    out = capsys.readouterr()
    return rc, out.out, out.err


def test_series_summary_reproduces_the_paper(run_cli):
    res = run_cli("simulate", "wear", "impact-golf-v28", "--param", "lam=1.81e6 Pa s/m",
                  "--solver", "series", "--points", "5001")
    out = res.stdout
    err = "".join(x for x in res.stderr.splitlines(keepends=True) if not PROGRESS_LINE.match(x))  # a slow machine's
    assert res.returncode == 0  # progress lines (time-stamped, written when the run outlasts two seconds)
    b = 1.81e6 * 130e-6 * 500e-6 / (0.046 * math.pi)
    assert err.startswith("warning: series: b = 0.814") and err.count("\n") == 1  # the accuracy warning names b
    peak = 5 * 12.0 / (4 * 0.0213) * RPM  # eq (9) at cos(phi t) = -(1 - b)/b
    line = next(x for x in out.splitlines() if "peak spin" in x)
    assert float(line.split()[2]) == pytest.approx(peak, rel=1e-6)
    end = 5 * 12.0 / 0.0213 * b * (1 - b) * RPM  # eq (10) at t_c
    assert f"spin {end:.6g} rpm" in out
    assert "series b       0.8141" in out


def test_csv_is_si_and_equals_the_api(capsys, tmp_path):
    csv = tmp_path / "w.csv"
    rc, out, err = run(capsys, "simulate", "wear", "impact-golf-v28", "--param", "lam=1810 kPa s/m",
                       "--solver", "exact", "--out", str(csv))
    assert rc == 0 and err == "" and f"wrote {csv}" in out
    df = pd.read_csv(csv)
    assert list(df.columns) == ["t", "u", "v", "omega", "theta", "force", "A"]
    ds = fl.load_dataset("impact-golf-v28")
    tr = fl.simulate("wear", ds, {"lam": 1.81e6}, solver="exact")
    assert np.array_equal(df["t"].to_numpy(), ds.t)  # the dataset's times, in seconds
    for col in ("u", "v", "omega", "theta", "force", "A"):
        assert np.allclose(df[col].to_numpy(), tr[col], rtol=1e-15, atol=0), col
    assert df["t"].iloc[-1] == pytest.approx(500e-6)


def test_coulomb_csv_has_normal_force_and_stick_time(capsys, tmp_path):
    csv = tmp_path / "c.csv"
    rc, out, _ = run(capsys, "simulate", "coulomb", "impact-golf-v28", "--param", "mu=0.3",
                     "--solver", "exact", "--points", "101", "--out", str(csv))
    assert rc == 0
    df = pd.read_csv(csv)
    assert list(df.columns) == ["t", "u", "v", "omega", "theta", "force", "N"] and len(df) == 101
    # without slip coupling the ball's slip stops once mu int N dt = m u0 (half-sine N, e = 0.8)
    m, u0, tc = 0.046, 12.0, 500e-6
    impulse = m * 28 * math.cos(math.radians(30)) * 1.8
    t_s = math.acos(1 - m * u0 / (0.3 * impulse / 2)) * tc / math.pi
    assert f"slip reached zero at t = {t_s * 1e6:.4g} µs" in out


def test_defaults_and_fixed_values_are_used(capsys):
    rc, out, _ = run(capsys, "simulate", "wear", "impact-golf-v28")
    assert rc == 0 and "lam = 1e+06 Pa s/m" in out  # the law's default
    rc, out, _ = run(capsys, "simulate", "couette", "incline-oil-a100", "--param", "h=40 um")
    assert rc == 0 and "eta = 0.1 Pa s" in out and "h = 4e-05 m" in out  # eta from the dataset's [fixed]
    assert "peak velocity" in out and "peak spin" not in out  # an incline block has no spin


def test_plot_and_toml_path(capsys, tmp_path):
    for ext in ("toml", "csv"):
        shutil.copy(builtin_dir() / f"incline-dry-d10.{ext}", tmp_path / f"d.{ext}")
    png, csv = tmp_path / "fig.png", tmp_path / "v.csv"
    rc, out, _ = run(capsys, "simulate", "wear", str(tmp_path / "d.toml"), "--param", "lam=2e4 Pa s/m",
                     "--plot", str(png), "--out", str(csv))
    assert rc == 0 and is_png(png.read_bytes()) and csv.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.csv", "d.toml", "fig.png", "v.csv"]


def test_failed_plot_writes_no_csv(capsys, tmp_path):
    csv = tmp_path / "x.csv"
    rc, _, err = run(capsys, "simulate", "wear", "impact-golf-v28", "--out", str(csv),
                     "--plot", str(tmp_path / "missing" / "fig.png"))
    assert rc == 2 and "fig.png" in err and not csv.exists()
    assert list(tmp_path.iterdir()) == []


def test_outcome_dataset(capsys, tmp_path):
    csv, png = tmp_path / "o.csv", tmp_path / "o.png"
    rc, out, _ = run(capsys, "simulate", "coulomb", "impact-outcome-synthetic", "--param", "mu=0.25",
                     "--solver", "exact", "--out", str(csv), "--plot", str(png))
    assert rc == 0 and is_png(png.read_bytes())
    df = pd.read_csv(csv)
    ds = fl.load_dataset("impact-outcome-synthetic")
    ref = predict_outcomes("coulomb", ds, {"mu": 0.25}, "exact")
    assert len(df) == len(ds) == 21
    for col in ("speed", "incidence", "rebound_spin", "tangential_cor", "rebound_angle"):
        assert np.allclose(df[col].to_numpy(), ref[col], rtol=1e-15), col
    assert "rebound_spin (the dataset's observable) [rpm]" in out and "rolled" in out


def test_an_outcome_dataset_gets_its_own_observable_on_screen_and_every_outcome_in_the_csv(capsys, tmp_path):
    """kharaz2001-tangential-cor observes the centre-of-mass e_T, not the contact point's: the screen shows
    that column under its name, and the CSV has every outcome the scene gives."""
    csv = tmp_path / "k.csv"
    rc, out, _ = run(capsys, "simulate", "coulomb", "kharaz2001-tangential-cor", "--param", "mu=0.09", "--out",
                     str(csv))
    ds = fl.load_dataset("kharaz2001-tangential-cor")
    ref = predict_outcomes("coulomb", ds, {"mu": 0.09}, "ode")
    df = pd.read_csv(csv)
    assert rc == 0 and ds.observable == "cm_tangential_cor" and "cm_tangential_cor (the dataset's observable)" in out
    assert {"cm_tangential_cor", "contact_rebound_angle", "psi1", "psi2"} <= set(df.columns)
    assert np.allclose(df["cm_tangential_cor"].to_numpy(), ref["cm_tangential_cor"], rtol=1e-12)
    first = next(line for line in out.splitlines() if line.startswith("3.9"))
    assert f"{ref['cm_tangential_cor'][0]:.4g}" in first.split()


@pytest.mark.parametrize("argv, match", [
    (["--law", "nope"], "unknown law 'nope'"),
    (["--law", "wear", "--param", "mu=0.3"], "law 'wear' has no parameter 'mu'"),
    (["--law", "wear", "--param", "lam=-1 Pa s/m"], "lam = .* outside its bounds"),
    (["--law", "wear", "--param", "lam=1e6"], "--param lam: .*no unit"),
    (["--law", "wear", "--param", "lam"], "--param 'lam': expected NAME=VALUE"),
    (["--law", "wear", "--solver", "rk4"], "unknown solver 'rk4'"),
    (["--law", "coulomb", "--solver", "series"], "series: law 'coulomb' has no series solution"),
    (["--law", "wear", "--rtol", "0"], "rtol must be a number in \\(0, 1\\)"),
    (["--law", "wear", "--points", "1"], "--points must be between 2 and"),
])
def test_errors_are_one_line(capsys, tmp_path, argv, match):
    out_csv = tmp_path / "never.csv"
    law, rest = argv[1], argv[2:]  # the table names the law as --law: the law comes first, as in 'fit'
    rc, out, err = run(capsys, "simulate", law, "impact-golf-v28", *rest, "--out", str(out_csv))
    lines = err.strip().splitlines()
    assert rc == 2 and len(lines) == 1 and lines[0].startswith("frictionlab")
    assert pytest.importorskip("re").search(match, lines[0]), lines[0]
    assert not out_csv.exists() and out == ""


def test_trajectory_and_dataset_as_dataframes_with_concise_reprs():
    """Both tables in SI with their units; the law's state is its own column (state_theta), never the
    rotation angle theta; the reprs are one line, not arrays."""
    import frictionlab as fl

    d = fl.load_dataset("spring-slider-aging")
    df = d.to_dataframe()
    assert list(df.columns) == list(d.columns) and df.attrs["units"]["t"] == "s" and len(df) == len(d)
    tr = fl.simulate("rate-state-aging", d, {})
    tdf = tr.to_dataframe()
    assert "state_theta" in tdf.columns and float(tdf["state_theta"].iloc[0]) > 0 and not tdf["theta"].any()
    assert "\n" not in repr(tr) and "state_theta" in repr(tr) and "array" not in repr(tr)
    assert "state_theta" in tr.csv_text().splitlines()[0].split(",")


def test_the_api_takes_quantity_strings_where_the_command_line_does():
    import frictionlab as fl
    from frictionlab.core.errors import UnitError

    ds = fl.load_dataset("impact-golf-v28")
    a = fl.simulate("wear", ds, {"lam": "1.81e6 Pa s/m"}, solver="exact")
    b = fl.simulate("wear", ds, {"lam": 1.81e6}, solver="exact")
    assert np.array_equal(a.omega, b.omega)
    with pytest.raises(UnitError, match="lam: '1.81e6' has no unit"):
        fl.simulate("wear", ds, {"lam": "1.81e6"})


def test_the_law_comes_first_as_in_fit_and_the_earlier_form_still_works_with_a_note(capsys):
    rc, new, err_new = run(capsys, "simulate", "wear", "impact-golf-v28", "--solver", "exact")
    rc_old, old, err = run(capsys, "simulate", "impact-golf-v28", "--law", "wear", "--solver", "exact")
    assert rc == rc_old == 0 and new == old and "note:" not in err_new
    assert "earlier form; write 'frictionlab simulate wear impact-golf-v28'" in err
    rc, _, err = run(capsys, "simulate", "wear", "impact-golf-v28", "--law", "coulomb")
    assert rc == 2 and "the law is given twice" in err


def test_a_spring_slider_csv_holds_the_laws_state_and_no_rotation_angle(capsys, tmp_path):
    csv = tmp_path / "s.csv"
    rc, out, _ = run(capsys, "simulate", "rate-state-aging", "spring-slider-aging", "--out", str(csv))
    df = pd.read_csv(csv)
    assert rc == 0 and "state_theta" in df.columns and "theta" not in df.columns and "omega" not in df.columns
    assert df["state_theta"].iloc[0] > 0 and "state_theta" in out and "spin" not in out
