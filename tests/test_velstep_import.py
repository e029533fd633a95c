"""Raw velocity-step records (time, displacement, friction, effective normal stress) imported as measured
spring-slider datasets: the records here are made by the test itself, in the raw format, from a known law."""
from __future__ import annotations

import re
import tomllib

import numpy as np
import pytest

import frictionlab as fl
from frictionlab.cli import main
from frictionlab.core.errors import DatasetError
from frictionlab.io.dataset import load_dataset
from frictionlab.io.velstep import analyse, dataset_toml, read_raw
from frictionlab.physics.scene import ConstantNormal, Scene, SpringLoad

TRUTH = {"mu0": 0.55, "a": 0.010, "b": 0.014, "Dc": 50e-6}
K = 0.01e6  # 0.01 1/um
T_STEP, T_END, CLOCK = 400.0, 1400.0, 8105.381  # the record's clock starts at CLOCK s
SIGMA = 2e-4
HEADER = "Time(s)\tDispl(microns)\tFriction\tEffectiveNormalstress(MPa)"


def _record(path, header=HEADER, times=(0.0, T_STEP), velocities=(2e-7, 2e-6), end=T_END, dt=0.2, seed=7):
    """Write a velocity-step record (default 0.2 -> 2 um/s at T_STEP, 5 Hz) in the raw format; the friction is
    the aging law's on a spring of stiffness K plus noise, the displacement the load point's plus 0.05 um noise."""
    t = np.arange(0.0, end, dt)
    scene = Scene(kind="spring-slider", mass=1.0, u0=velocities[0], duration=end, normal=ConstantNormal(1.0),
                  spring=SpringLoad(K, times, velocities))
    mu = fl.simulate("rate-state-aging", scene, TRUTH, t=t).load
    edges = [*times[1:], np.inf]
    x = sum(v * np.clip(t - a, 0.0, b - a) for a, b, v in zip(times, edges, velocities))
    rng = np.random.default_rng(seed)
    rows = [header] + [f"{a + CLOCK:.6f}\t{(b + 1e-3) * 1e6 + rng.normal(0, 0.05):.6f}\t{c:.6f}\t"
                       f"{30 + rng.normal(0, 0.01):.6f}" for a, b, c in zip(t, x, mu + rng.normal(0.0, SIGMA, t.size))]
    path.write_text("\n".join(rows) + "\n")
    return mu


def test_import_finds_the_step_its_fitted_velocities_and_a_stiffness_start(tmp_path):
    _record(tmp_path / "raw.txt")
    imp = analyse(read_raw(tmp_path / "raw.txt"), "vs")
    (st,), (w,) = imp.seg.steps, imp.windows
    assert abs(st.time - (CLOCK + T_STEP)) < 4 * st.time_se and st.time_se < 0.05
    assert imp.velocities == pytest.approx((2e-7, 2e-6), rel=1e-3)  # fitted, not rounded set points
    assert imp.velocities != (2e-7, 2e-6)
    assert (w.a, w.b) == (0, 7000) and w.times[1] == pytest.approx(T_STEP, abs=4 * st.time_se)
    assert K / 2 < w.stiffness < 2 * K  # a start, fitted afterwards


def test_the_dataset_keeps_the_contract_with_the_fit(tmp_path):
    """CSV t,x,mu with every sample; TOML spring-slider, mu, [scene.spring] times exact to the microsecond,
    fitted velocities, [noise] estimated with an AR(p) model chosen by the data and no sigma, provenance measured."""
    _record(tmp_path / "raw.txt")
    out = tmp_path / "out"
    out.mkdir()
    assert main(["datasets", "import", "velstep", str(tmp_path / "raw.txt"), "--name", "vs", "--out", str(out),
                 "--license", "MIT", "--citation", "nobody"]) == 0
    meta = tomllib.loads((out / "vs.toml").read_text())
    assert meta["kind"] == "spring-slider" and meta["observable"] == "mu"
    assert meta["noise"] == {"kind": "estimated", "correlation": "arp"}
    assert "trend" not in (out / "vs.toml").read_text().split("[provenance]")[0]
    spring = meta["scene"]["spring"]
    assert spring["times"][0] == "0 s" and spring["stiffness"].endswith(" 1/um")
    assert all(v.endswith(" um/s") for v in spring["velocities"])
    imp = analyse(read_raw(tmp_path / "raw.txt"), "vs")
    step = imp.seg.steps[0].time - imp.raw.t[0]
    assert abs(float(spring["times"][1].split()[0]) - step) < 1e-6
    assert meta["provenance"]["kind"] == "measured" and meta["provenance"]["license"] == "MIT"
    assert {"source", "citation", "method", "command"} <= set(meta["provenance"])
    lines = [x for x in (out / "vs.csv").read_text().splitlines() if not x.startswith("#")]
    assert lines[0] == "t,x,mu" and len(lines) - 1 == 7000  # every sample
    d = load_dataset(out / "vs.toml")
    assert d.provenance.kind == "measured" and len(d) == 7000 and d.t[0] == 0.0
    assert d.time_zero == pytest.approx(CLOCK) and d.scene.spring.times[1] == pytest.approx(step, abs=1e-6)


def test_several_steps_and_a_hold_import_as_one_dataset_each_or_one_joint_dataset(tmp_path, capsys):
    times, vs = (0.0, 300.0, 600.0, 700.0), (2e-6, 2e-7, 0.0, 2e-6)
    _record(tmp_path / "raw.txt", times=times, velocities=vs, end=1000.0)
    out = tmp_path / "out"
    out.mkdir()
    assert main(["datasets", "import", "velstep", str(tmp_path / "raw.txt"), "--name", "exp", "--out", str(out),
                 "--steps", "3"]) == 0
    text = capsys.readouterr().out
    assert "3 velocity steps" in text and "hold from lines" in text
    assert "step  line" in text and "V before [um/s]" in text  # the table
    # the hold has no steady state: the stop and the restart share one window, which starts at steady sliding
    assert sorted(p.name for p in out.iterdir()) == [f"exp-step{i}.{e}" for i in (1, 2) for e in ("csv", "toml")]
    assert "holds steps 2 to 3, simulated through" in text and "a hold (the load point at rest)" in text
    d2 = load_dataset(out / "exp-step2.toml")
    assert d2.scene.spring.velocities == pytest.approx((2e-7, 0.0, 2e-6), abs=1e-9)
    d1 = load_dataset(out / "exp-step1.toml")
    assert len(d1) + len(d2) <= 5000  # disjoint windows
    assert main(["datasets", "import", "velstep", str(tmp_path / "raw.txt"), "--name", "whole", "--out", str(out),
                 "--joint"]) == 0
    d = load_dataset(out / "whole.toml")
    assert len(d) == 5000 and d.scene.spring.velocities == pytest.approx(vs, abs=1e-9)
    assert d.scene.spring.times == pytest.approx(times, abs=0.05)


def test_steps_expected_and_found_must_agree(tmp_path, capsys):
    _record(tmp_path / "raw.txt")
    assert main(["datasets", "import", "velstep", str(tmp_path / "raw.txt"), "--name", "vs", "--out", str(tmp_path),
                 "--steps", "3"]) == 2
    assert re.search(r"raw.txt: expected 3 velocity steps \(--steps\), found 1: line 200[23] \(t = 8505\.38",
                     capsys.readouterr().err)


def test_a_given_stiffness_is_the_start_and_a_bad_one_names_the_option(tmp_path, capsys):
    _record(tmp_path / "raw.txt")
    imp = analyse(read_raw(tmp_path / "raw.txt"), "vs", stiffness=2e3)
    text = dataset_toml(imp, imp.windows[0])
    assert 'stiffness = "0.002 1/um"   # given with --stiffness' in text
    for bad in ("-0.01 1/um", "0 1/um", "nan 1/um"):
        assert main(["datasets", "import", "velstep", str(tmp_path / "raw.txt"), "--name", "vs", "--out",
                     str(tmp_path), f"--stiffness={bad}"]) == 2
        err = capsys.readouterr().err
        assert err.startswith("frictionlab: error: --stiffness") and ".toml" not in err, err


@pytest.mark.slow
def test_the_imported_step_is_fitted_back_with_free_stiffness(tmp_path):
    _record(tmp_path / "raw.txt")
    out = tmp_path / "out"
    out.mkdir()
    assert main(["datasets", "import", "velstep", str(tmp_path / "raw.txt"), "--name", "vs", "--out", str(out)]) == 0
    r = fl.fit("rate-state-aging", out / "vs.toml", free={"spring.stiffness": (1e3, 1e5)})
    assert r.ok, r.reason
    for name in ("a", "b", "Dc"):
        p = r.params[name]
        assert abs(p.value - TRUTH[name]) < 4 * p.stderr, (name, p.value, p.stderr)


def test_the_command_refuses_bad_records_and_writes_nothing(tmp_path, capsys):
    _record(tmp_path / "raw.txt")
    out = tmp_path / "out"
    out.mkdir()
    argv = ["datasets", "import", "velstep", str(tmp_path / "raw.txt"), "--name", "vs", "--out", str(out)]
    assert main(argv) == 0
    assert "load point" not in capsys.readouterr().err
    assert main(argv) == 2 and "exists" in capsys.readouterr().err
    (tmp_path / "bad.txt").write_text("t x mu sn\n1 2 3 4\n")
    assert main(["datasets", "import", "velstep", str(tmp_path / "bad.txt"), "--name", "b", "--out", str(out)]) == 2
    assert "bad.txt: line 1: header 't x mu sn'; expected four columns" in capsys.readouterr().err
    assert sorted(p.name for p in out.iterdir()) == ["vs.csv", "vs.toml"]  # nothing written for the bad record


def test_raw_reader_names_the_line_of_a_bad_row(tmp_path):
    _record(tmp_path / "raw.txt")
    lines = (tmp_path / "raw.txt").read_text().splitlines()
    lines[5] = "8106.0\t1000.0\tnan\t30.0"
    (tmp_path / "raw.txt").write_text("\n".join(lines) + "\n")
    with pytest.raises(DatasetError, match=r"raw.txt: line 6: expected four finite numbers"):
        read_raw(tmp_path / "raw.txt")


def test_blank_lines_keep_the_line_numbers_of_the_file(tmp_path):
    _record(tmp_path / "raw.txt")
    lines = (tmp_path / "raw.txt").read_text().splitlines()
    lines[9:9] = ["", "  "]
    lines[20] = "\t".join(lines[20].split("\t")[:3] + ["-30"])  # a negative normal stress on line 21
    (tmp_path / "raw.txt").write_text("\n".join(lines) + "\n")
    with pytest.raises(DatasetError, match=r"raw.txt: line 21: normal stress must be positive"):
        read_raw(tmp_path / "raw.txt")


def test_other_header_spellings_of_the_source_are_read(tmp_path):
    _record(tmp_path / "raw.txt", header="Time(s)\tDispl(microns)\tFriction\tEffective_Normal_stress(MPa)")
    assert read_raw(tmp_path / "raw.txt").sn.mean() == pytest.approx(30e6, rel=1e-3)


def test_a_record_headed_normal_stress_says_normal_not_effective(tmp_path):
    _record(tmp_path / "raw.txt", header="Time(s)\tDispl(microns)\tFriction\tNormal_stress(MPa)")
    raw = read_raw(tmp_path / "raw.txt")
    assert raw.stress == "normal stress" and raw.sn.mean() == pytest.approx(30e6, rel=1e-3)
    _record(tmp_path / "eff.txt")
    assert read_raw(tmp_path / "eff.txt").stress == "effective normal stress"
