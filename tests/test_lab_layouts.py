"""Raw records in other laboratories' layouts (``--columns``; io.layout): the measured basalt step rewritten as
time in ms, displacement in mm, shear and normal stress in MPa, comma-separated (in a temporary folder, never in
the repository), fits to the same a, b and Dc as the record in its own layout; the grammar's refusals."""
from __future__ import annotations

import numpy as np
import pytest

import frictionlab as fl
from frictionlab.cli import main
from frictionlab.core.errors import FrictionLabError
from frictionlab.io import external
from frictionlab.io.velstep import analyse, dataset_toml, read_raw

BASALT = external.locate("basalt-velstep4")
COLUMNS = ('time="Time (ms)" ms, displacement="LP disp (mm)" mm, shear="Shear stress (MPa)" MPa, '
           'normal="Normal stress (MPa)" MPa')


@pytest.mark.skipif(BASALT is None, reason="the measured record basalt-velstep4 is not placed in "
                                           "../shared/data/steadystate (or FRICTIONLAB_RAW_DATA); it is not held in "
                                           "the repository")
def test_the_basalt_step_in_ms_mm_and_mpa_fits_as_in_its_own_layout(tmp_path, capsys):
    rows = np.loadtxt(BASALT, skiprows=1)  # Time(s) Displ(microns) Friction Normal_stress(MPa)
    with open(tmp_path / "basalt.csv", "w") as fh:
        fh.write("Time (ms),LP disp (mm),Shear stress (MPa),Normal stress (MPa)\n")
        for t, x, mu, sn in rows.tolist():
            fh.write(f"{t * 1e3!r},{x / 1e3!r},{mu * sn!r},{sn!r}\n")
    (tmp_path / "out").mkdir()
    assert main(["datasets", "import", "velstep", str(BASALT), "--name", "own", "--out", str(tmp_path / "out")]) == 0
    assert main(["datasets", "import", "velstep", str(tmp_path / "basalt.csv"), "--name", "lab", "--out",
                 str(tmp_path / "out"), "--columns", COLUMNS]) == 0
    assert "friction = Shear stress (MPa) / Normal stress (MPa)" in capsys.readouterr().out
    own, lab = (fl.fit("rate-state-aging", tmp_path / "out" / f"{n}.toml") for n in ("own", "lab"))
    assert own.ok and lab.ok
    for name in ("a", "b", "Dc"):
        se = own.stderr(name)
        assert se > 0 and abs(own.value(name) - lab.value(name)) < 0.1 * se, (name, own.value(name), lab.value(name), se)


def _step(n=3000, dt=0.1, ts=150.0, v=(1.0, 10.0), seed=0):
    """A synthetic step: time [s], load-point displacement [um], friction."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    x = v[0] * t + (v[1] - v[0]) * np.clip(t - ts, 0, None) + rng.normal(0, 0.05, n)
    return t, x, 0.6 + rng.normal(0, 5e-4, n)


def test_the_same_grammar_in_python_reads_a_headed_space_separated_export_in_kn(tmp_path):
    """An xlook-style export: metadata lines, a header, a row of units, columns by name, spaces between them,
    forces in kN: friction is shear force over normal force, the skipped lines said."""
    t, x, mu = _step()
    fn = 50.0 + np.zeros_like(t)
    text = ["experiment p1234, synthetic", "rec   lp_disp  tau_f  sig_n  time", "-   mm  kN  kN  ms"]
    text += [f"{i} {b / 1e3!r} {c * f!r} {f!r} {a * 1e3!r}" for i, (a, b, c, f) in enumerate(zip(t.tolist(),
             x.tolist(), mu.tolist(), fn.tolist()))]
    (tmp_path / "p1234.txt").write_text("\n".join(text) + "\n")
    raw = read_raw(tmp_path / "p1234.txt", columns="time=time ms, displacement=LP_DISP mm, shear=tau_f kN, "
                                                   "normal=sig_n kN")
    assert raw.t == pytest.approx(t, abs=1e-12) and raw.x_um == pytest.approx(x, abs=1e-9)
    assert raw.mu == pytest.approx(mu, rel=1e-12) and raw.sn == pytest.approx(5e4) and raw.stress == "normal force"
    assert raw.line(0) == 4 and any("1 row of text after the header skipped (line 3)" in n for n in raw.notes)
    imp = analyse(raw, "p1234")
    assert len(imp.seg.steps) == 1 and abs(imp.seg.steps[0].time - 150.0) < 5 * imp.seg.steps[0].time_se
    assert "50 kN normal force" in dataset_toml(imp, imp.windows[0])


def test_columns_by_position_in_a_file_without_a_header(tmp_path):
    t, x, mu = _step()
    (tmp_path / "bare.tsv").write_text("\n".join(f"{a!r}\t{b!r}\t{c!r}" for a, b, c in zip(t.tolist(), x.tolist(),
                                                                                          mu.tolist())) + "\n")
    raw = read_raw(tmp_path / "bare.tsv", columns="time=#1 s, displacement=#2 um, friction=#3")
    assert raw.sn is None and raw.mu == pytest.approx(mu) and raw.line(0) == 1
    imp = analyse(raw, "bare")
    assert "a unit load" in dataset_toml(imp, imp.windows[0])


@pytest.mark.parametrize("spec, error", [
    ("time=t s, displacement=x um", "columns: give friction=NAME, or shear=NAME UNIT with normal=NAME UNIT"),
    ("time=t s, displacement=x um, friction=mu, speed=v um/s", "columns: unknown column 'speed'"),
    ("time=t, displacement=x um, friction=mu", "columns: time=t: no unit; write it like 'time=t s'"),
    ("time=t s, displacement=x kg, friction=mu", r"columns: displacement=x: unit 'kg' is \[mass\], expected \[length\]"),
    ("time=t s, displacement=x um, shear=tau MPa", "columns: shear needs normal=NAME UNIT"),
    ("time=t s, displacement=x um, shear=tau MPa, normal=sn kN", "columns: shear is a stress .MPa. and normal a force"),
    ("time=t s, displacement=x um, shear=tau MPa, normal=sn um", "columns: normal=sn: unit 'um' is neither a stress"),
    ("time=t s, time=u s, displacement=x um, friction=mu", "columns: time is given twice"),
    ("time=t s,, displacement=x um, friction=mu", "columns: .* holds an empty item"),
    ("time t s, displacement=x um, friction=mu", "columns: 'time t s': expected ROLE=NAME UNIT"),
    ("time=t s, displacement=t um, friction=mu", "columns: column 't' is named for two roles"),
])
def test_a_layout_that_cannot_be_read_is_refused_naming_the_column(spec, error, tmp_path):
    (tmp_path / "r.csv").write_text("t,x,mu\n0,0,0.6\n")
    with pytest.raises(FrictionLabError, match=error):
        read_raw(tmp_path / "r.csv", columns=spec)


def test_a_column_the_header_does_not_name_and_a_bad_cell_are_refused_with_the_line(tmp_path):
    t, x, mu = _step()
    rows = ["Time,Disp,Mu"] + [f"{a!r},{b!r},{c!r}" for a, b, c in zip(t.tolist(), x.tolist(), mu.tolist())]
    rows[500] = "49.9,49.9,n/a"
    (tmp_path / "r.csv").write_text("\n".join(rows) + "\n")
    with pytest.raises(FrictionLabError, match=r"r.csv: no header line names the column friction=Friction given; line "
                                               r"1 has 'time', 'disp', 'mu'"):
        read_raw(tmp_path / "r.csv", columns="time=Time s, displacement=Disp um, friction=Friction")
    with pytest.raises(FrictionLabError, match=r"r.csv: line 501: friction=Mu: 'n/a' is not a finite number"):
        read_raw(tmp_path / "r.csv", columns="time=Time s, displacement=Disp um, friction=Mu")


def test_crlf_lines_and_text_before_the_data_with_columns_by_position(tmp_path):
    """Windows line ends, a title and a header before the data: columns by position find the first row of
    numbers in its own separator, and say which rows were skipped."""
    t, x, mu = _step()
    rows = "".join(f"{a!r},{b!r},{c!r}\r\n" for a, b, c in zip(t.tolist(), x.tolist(), mu.tolist()))
    (tmp_path / "r.csv").write_bytes(("Run 7 title\r\nt,x,mu\r\n" + rows).encode())
    raw = read_raw(tmp_path / "r.csv", columns="time=#1 s, displacement=#2 um, friction=#3")
    assert raw.notes == ("2 rows of text before the data skipped (lines 1 to 2)",) and raw.line(0) == 3
    assert raw.t == pytest.approx(t) and raw.mu == pytest.approx(mu)
