"""Dataset loading: SI conversion, provenance, and one-line errors naming file and field."""
import math
import shutil
from pathlib import Path

import numpy as np
import pytest

import frictionlab as fl
from frictionlab.core.errors import DatasetError
from frictionlab.io.dataset import builtin_dir, builtin_names

RPM = 2 * math.pi / 60


def test_every_builtin_loads_with_honest_provenance():
    names = builtin_names()
    assert {"impact-golf-v28", "impact-golf-v61", "impact-area-v32"} <= set(names)
    for name in names:
        d = fl.load_dataset(name)
        # the Arakawa paper publishes no measurements; measured sets are transcriptions with a cited source
        assert d.provenance.kind in ("reconstructed", "synthetic", "measured")
        if d.provenance.kind == "measured":
            assert "MEASURED" in d.description and "@" in d.provenance.source  # repository path @ commit
        assert d.provenance.command == "frictionlab datasets rebuild"
        assert np.all(np.isfinite(d.y)) and (d.sigma > 0 if d.noise_kind != "none" else d.provenance.kind == "reconstructed")
        if d.provenance.kind == "synthetic":
            assert d.provenance.seed is not None and "law" in d.provenance.truth
            assert "SYNTHETIC" in d.description


def test_golf_units_become_si():
    d = fl.load_dataset("impact-golf-v28")
    assert d.t[1] == pytest.approx(10e-6)
    assert d.observable == "theta" and d.noise_kind == "none" and d.noise == {}  # noise-free: no sigma at all
    assert d.stated["omega_peak"] == pytest.approx((6700 * RPM, 100 * RPM))
    assert d.stated["theta_max"] == pytest.approx((math.radians(13), math.radians(1)))
    s = d.scene
    assert (s.mass, s.radius, s.u0) == pytest.approx((0.046, 0.0213, 12.0))
    assert s.area.peak == pytest.approx(130e-6) and s.area.contact_time == pytest.approx(500e-6)
    # half-sine normal force: impulse m v_n (1 + e) with v_n = 28 cos 30 deg, e = 0.8 (assumed)
    assert s.normal.impulse == pytest.approx(0.046 * 28 * math.cos(math.radians(30)) * 1.8, rel=1e-4)


@pytest.mark.parametrize("speed", [28, 61])
def test_golf_reconstruction_agrees_with_every_stated_number(speed):
    d = fl.load_dataset(f"impact-golf-v{speed}")
    rep = d.reported
    q = lambda s: fl.core.units.to_si(s, {"rpm": "rad/s", "us": "s", "deg": "rad"}[s.split()[1]], "test")  # noqa: E731
    w = d.columns["omega"]
    i = int(np.argmax(w))
    assert w[0] == 0.0
    assert w[i] == pytest.approx(q(rep["omega_peak"]), rel=1e-6)
    assert d.t[i] == pytest.approx(q(rep["t_peak"]))
    assert w[-1] == pytest.approx(q(rep["omega_at_contact_end"]), rel=1e-6)
    assert d.t[-1] == pytest.approx(q(rep["contact_time"]))
    assert d.columns["theta"].max() == pytest.approx(q(rep["theta_max"]), rel=1e-6)
    assert np.all(np.diff(w[: i + 1]) > 0) and np.all(np.diff(w[i + 1:]) < 0)  # one peak


def test_area_series_matches_stated_peak():
    d = fl.load_dataset("impact-area-v32")
    i = int(np.argmax(d.y))
    assert d.y[i] == pytest.approx(150e-6) and d.t[i] == pytest.approx(220e-6)


@pytest.fixture
def golf_copy(tmp_path):
    for ext in (".csv", ".toml"):
        shutil.copy(builtin_dir() / f"impact-golf-v28{ext}", tmp_path / f"g{ext}")
    return tmp_path / "g.toml"


def _edit(path: Path, old: str, new: str):
    text = path.read_text()
    assert old in text, old
    path.write_text(text.replace(old, new, 1))


@pytest.mark.parametrize("suffix, old, new, message", [
    (".toml", 'name = "impact-golf-v28"\n', "", r"g.toml: missing required key 'name'"),
    (".toml", 'omega = "rpm"', 'omega = "blargs"', r"g.toml: columns.omega: unknown unit 'blargs'"),
    (".toml", 'mass = "46 g"', 'mass = "46 m"', r"g.toml: scene.mass: '46 m' is \[length\], expected \[mass\]"),
    (".toml", 'mass = "46 g"', 'mass = "-46 g"', r"g.toml: scene.mass must be positive"),
    (".toml", 'mass = "46 g"', "mass = 0.046", r"g.toml: scene.mass: 0.046 has no unit"),
    (".toml", 'peak = "130 mm^2"', 'peak = "-130 mm^2"', r"g.toml: scene.area.peak must be positive"),
    (".toml", 'observable = "theta"', 'observable = "spin_rate"', r"observable 'spin_rate' is not declared"),
    (".toml", 'kind = "reconstructed"', 'kind = "vibes"', r"provenance.kind = 'vibes', expected one of"),
    (".toml", "[columns]", "[columns", r"g.toml: TOML does not parse"),
    (".csv", "\n10,", "\n0,", r"g.csv: column 't' must increase strictly"),
    (".csv", "\n20,", "\n20,nan", r"g.csv: column 'omega' line 5: .* is not a finite number"),
    (".csv", "\n20,", "\n20,inf", r"g.csv: column 'omega' line 5: .* is not a finite number"),
    (".csv", "t,omega,theta", "t,spin,theta", r"g.csv: missing column 'omega' declared in g.toml"),
])
def test_bad_input_is_one_line_naming_file_and_field(golf_copy, suffix, old, new, message):
    _edit(golf_copy.with_suffix(suffix), old, new)
    with pytest.raises(DatasetError, match=message) as info:
        fl.load_dataset(golf_copy)
    assert "\n" not in str(info.value)


def test_empty_csv(golf_copy):
    golf_copy.with_suffix(".csv").write_text("")
    with pytest.raises(DatasetError, match=r"g.csv: file is empty"):
        fl.load_dataset(golf_copy)


def test_unknown_dataset_lists_builtins():
    with pytest.raises(DatasetError, match=r"unknown dataset 'nope'; built-in: .*impact-golf-v28"):
        fl.load_dataset("nope")


def test_same_data_in_other_units_loads_to_the_same_si(golf_copy):
    d1 = fl.load_dataset(golf_copy)
    csv = golf_copy.with_suffix(".csv")
    rows = [line for line in csv.read_text().splitlines() if not line.startswith("#")]
    out = ["t,omega,theta"]
    for line in rows[1:]:
        t, w, th = map(float, line.split(","))
        out.append(f"{t * 1e-6!r},{w * RPM!r},{math.radians(th)!r}")
    csv.write_text("\n".join(out) + "\n")
    _edit(golf_copy, 't = "us"', 't = "s"')
    _edit(golf_copy, 'omega = "rpm"', 'omega = "rad/s"')
    _edit(golf_copy, 'theta = "deg"', 'theta = "rad"')
    d2 = fl.load_dataset(golf_copy)
    for col in ("t", "omega", "theta"):
        assert np.allclose(d1.columns[col], d2.columns[col], rtol=1e-14, atol=0)


def test_datasets_cli_lists_provenance(run_cli):
    out = run_cli("datasets")
    assert out.returncode == 0, out.stderr
    assert "impact-golf-v28" in out.stdout and "reconstructed" in out.stdout and "synthetic" in out.stdout


def test_cli_error_is_one_line_exit_2(run_cli, golf_copy):
    _edit(golf_copy, 'mass = "46 g"', 'mass = "46 m"')
    out = run_cli("datasets", "show", golf_copy)
    assert out.returncode == 2
    assert out.stderr.count("\n") == 1 and "scene.mass" in out.stderr and "Traceback" not in out.stderr
    out = run_cli("--debug", "datasets", "show", golf_copy)
    assert out.returncode != 0 and "Traceback" in out.stderr


def test_group_key_declares_the_group_and_nothing_is_inferred_from_names(golf_copy):
    from frictionlab.inference.verdicts.answers import group_of

    d = fl.load_dataset(golf_copy)
    assert d.group == "impact-golf" and group_of(d) == "impact-golf"  # the built-in file declares it
    _edit(golf_copy, 'group = "impact-golf"\n', '')
    d = fl.load_dataset(golf_copy)
    assert d.group == "" and group_of(d) == d.name  # no key: its own group, never "impact-golf" from the name
    _edit(golf_copy, 'kind = "impact"', 'group = "golf-balls"\nkind = "impact"')
    d = fl.load_dataset(golf_copy)
    assert d.group == "golf-balls" and group_of(d) == "golf-balls"
    kharaz = [fl.load_dataset(n) for n in builtin_names() if n.startswith("kharaz2001-")]
    assert len(kharaz) == 3 and {group_of(k) for k in kharaz} == {"kharaz2001"}
