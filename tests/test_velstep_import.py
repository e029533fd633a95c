"""Raw velocity-step records (time, displacement, friction, effective normal stress) imported as measured
spring-slider datasets: the record here is made by the test itself, in the raw format, from a known law."""
from __future__ import annotations

import numpy as np
import pytest

import frictionlab as fl
from frictionlab.cli import main
from frictionlab.core.errors import DatasetError
from frictionlab.io.dataset import load_dataset
from frictionlab.io.velstep import read_raw, velstep_dataset
from frictionlab.physics.scene import ConstantNormal, Scene, SpringLoad

TRUTH = {"mu0": 0.55, "a": 0.010, "b": 0.014, "Dc": 50e-6}
K = 0.01e6  # 0.01 1/um
T_STEP, T_END, CLOCK = 400.0, 1400.0, 8105.381  # the record's clock starts at CLOCK s
SIGMA = 2e-4


def _record(path, trend=0.0, header="Time(s)\tDispl(microns)\tFriction\tEffectiveNormalstress(MPa)"):
    """Write a velocity step 0.2 -> 2 um/s sampled at 5 Hz, as the raw format has it; returns the slider's load."""
    t = np.arange(0.0, T_END, 0.2)
    scene = Scene(kind="spring-slider", mass=1.0, u0=2e-7, duration=T_END, normal=ConstantNormal(1.0),
                  spring=SpringLoad(K, (0.0, T_STEP), (2e-7, 2e-6)))
    mu = fl.simulate("rate-state-aging", scene, TRUTH, t=t).load
    x = np.where(t < T_STEP, 2e-7 * t, 2e-7 * T_STEP + 2e-6 * (t - T_STEP))
    rng = np.random.default_rng(7)
    noisy = mu + trend * x + rng.normal(0.0, SIGMA, t.size)
    rows = [header] + [f"{a + CLOCK:.6f}\t{(b + 1e-3) * 1e6:.6f}\t{c:.6f}\t{30 + rng.normal(0, 0.01):.6f}"
                       for a, b, c in zip(t, x, noisy)]
    path.write_text("\n".join(rows) + "\n")
    return mu


def test_import_finds_the_step_the_velocities_and_the_stiffness(tmp_path):
    _record(tmp_path / "raw.txt")
    toml, csv, imp = velstep_dataset(tmp_path / "raw.txt", "vs", points=300, source="test", license="MIT",
                                     citation="nobody")
    assert imp.velocities == (2e-7, 2e-6)
    assert imp.step_times[0] == pytest.approx(T_STEP, abs=0.2)
    assert imp.time_zero == pytest.approx(CLOCK)
    assert imp.stiffness == pytest.approx(K, rel=0.3)  # a starting value only: it is fitted afterwards
    assert imp.sigma == pytest.approx(SIGMA, rel=0.1)
    assert imp.trend == 0.0  # the record is kept as measured unless --detrend
    assert 250 <= len(imp.index) <= 300
    dense = np.diff(imp.index[(imp.index > T_STEP / 0.2) & (imp.index < T_STEP / 0.2 + 50)])
    assert dense.size and dense.min() == 1  # every sample kept just after the step
    (tmp_path / "vs.toml").write_text(toml)
    (tmp_path / "vs.csv").write_text(csv)
    d = load_dataset(tmp_path / "vs.toml")
    assert d.provenance.kind == "measured" and d.provenance.license == "MIT" and d.provenance.citation == "nobody"
    assert d.t[0] == 0.0 and d.time_zero == pytest.approx(CLOCK)
    assert d.scene.spring.times == pytest.approx((0.0, T_STEP), abs=0.2)


def test_a_trend_before_the_step_is_measured_and_removed(tmp_path):
    mu = _record(tmp_path / "raw.txt", trend=-20.0)  # -2e-5 per um
    _, _, imp = velstep_dataset(tmp_path / "raw.txt", "vs", points=300, detrend=True)
    assert imp.trend == pytest.approx(-20.0, rel=0.1)
    assert np.std(imp.mu - mu) < 2 * SIGMA
    _, _, kept = velstep_dataset(tmp_path / "raw.txt", "vs", points=300)
    assert kept.trend == 0.0 and np.std(kept.mu - mu) > 10 * SIGMA


@pytest.mark.slow
def test_the_imported_step_is_fitted_back_with_free_stiffness(tmp_path):
    _record(tmp_path / "raw.txt")
    toml, csv, _ = velstep_dataset(tmp_path / "raw.txt", "vs", points=200)
    (tmp_path / "vs.toml").write_text(toml)
    (tmp_path / "vs.csv").write_text(csv)
    r = fl.fit("rate-state-aging", tmp_path / "vs.toml", free={"spring.stiffness": (1e3, 1e5)})
    assert r.ok, r.reason
    for name in ("a", "b", "Dc"):
        p = r.params[name]
        assert abs(p.value - TRUTH[name]) < 4 * p.stderr, (name, p.value, p.stderr)
    k = r.params["spring.stiffness"]
    assert abs(k.value - K) < 4 * k.stderr


def test_the_command_writes_a_pair_that_loads_and_refuses_bad_records(tmp_path, capsys):
    _record(tmp_path / "raw.txt")
    out = tmp_path / "out"
    out.mkdir()
    argv = ["datasets", "import", "velstep", str(tmp_path / "raw.txt"), "--name", "vs", "--out", str(out),
            "--points", "200", "--license", "MIT"]
    assert main(argv) == 0
    assert "load point 0.2 um/s -> 2 um/s" in capsys.readouterr().out
    assert load_dataset(out / "vs.toml").provenance.kind == "measured"
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


def test_other_header_spellings_of_the_source_are_read(tmp_path):
    _record(tmp_path / "raw.txt", header="Time(s)\tDispl(microns)\tFriction\tEffective_Normal_stress(MPa)")
    assert read_raw(tmp_path / "raw.txt").sn.mean() == pytest.approx(30e6, rel=1e-3)


def test_a_record_headed_normal_stress_says_normal_not_effective(tmp_path):
    _record(tmp_path / "raw.txt", header="Time(s)\tDispl(microns)\tFriction\tNormal_stress(MPa)")
    raw = read_raw(tmp_path / "raw.txt")
    assert raw.stress == "normal stress" and raw.sn.mean() == pytest.approx(30e6, rel=1e-3)
    _record(tmp_path / "eff.txt")
    assert read_raw(tmp_path / "eff.txt").stress == "effective normal stress"
