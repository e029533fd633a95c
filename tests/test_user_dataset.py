"""A user's own dataset: a template for every kind that explains itself, and a time column that starts at 0
or says where its zero lies (time_zero); never an offset guessed, never epoch seconds fitted silently."""
from __future__ import annotations

import tomllib

import numpy as np
import pytest

from frictionlab.cli import main
from frictionlab.core.errors import DatasetError
from frictionlab.io.dataset import load_dataset
from frictionlab.io.template import KINDS, template
from frictionlab.physics.scene import KINDS as SCENE_KINDS
from frictionlab.solve.outcome import OUTCOMES


def test_there_is_a_template_for_every_scene_kind():
    assert set(KINDS) == set(SCENE_KINDS)


@pytest.mark.parametrize("kind", KINDS)
def test_template_explains_noise_kinds_and_every_observable(kind):
    toml, _ = template(kind, "mine")
    meta = tomllib.loads(toml)
    assert "noise" in meta
    for word in ('kind = "estimated"', 'kind = "known"', 'kind = "none"', "no [noise] table"):
        assert word in toml
    observables = {"impact": ["omega", "theta", "v", "u", "A", "N"], "incline": ["v", "u"],
                   "impact-outcome": list(OUTCOMES), "spring-slider": ["mu"]}[kind]
    head = toml[toml.index("observable ="):toml.index("description =")]
    for name in observables:
        assert name in head, name
    assert ("[scene.materials]" in toml and "[scene.compliance]" in toml) == (kind in ("impact", "impact-outcome"))


@pytest.mark.parametrize("name", ["../evil", "a/b", "", ".hidden", "x" * 300])
def test_template_names_follow_the_file_name_grammar(name, tmp_path, capsys):
    with pytest.raises(DatasetError, match="--name"):
        template("impact", name)
    assert main(["datasets", "template", "impact", "--name", name, "--out", str(tmp_path)]) == 2
    assert list(tmp_path.iterdir()) == []


def _pair(tmp_path, kind, shift, unit_line=None, time_zero=None):
    toml, csv = template(kind, "mine")
    lines = csv.splitlines()
    head = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    rows = [line.split(",") for line in lines[head + 1:]]
    body = [",".join([f"{float(r[0]) + shift:.12g}"] + r[1:]) for r in rows]
    toml = toml.replace('time_zero = "0 us"', "").replace('time_zero = "0 s"', "")
    if time_zero is not None:
        toml = f'time_zero = "{time_zero}"\n' + toml
    (tmp_path / "mine.toml").write_text(toml)
    (tmp_path / "mine.csv").write_text("\n".join(lines[:head + 1] + body) + "\n")
    return tmp_path / "mine.toml"


def test_a_time_column_not_at_zero_is_an_error_that_says_how_to_declare_it(tmp_path):
    with pytest.raises(DatasetError, match=r"mine.csv: column 't' starts at 10, not 0: .*time_zero = \"10 <unit>\""):
        load_dataset(_pair(tmp_path, "impact", 10.0))


@pytest.mark.parametrize("kind", ["impact", "incline", "spring-slider"])
def test_the_template_as_written_keeps_the_time_zero_check(kind, tmp_path):
    """The template declares no time_zero (commented): a CSV pasted into it that starts late is an error."""
    toml, csv = template(kind, "mine")
    assert "time_zero" not in tomllib.loads(toml) and "# time_zero" in toml
    lines = csv.splitlines()
    head = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    body = [",".join([f"{float(r.split(',')[0]) + 10:.12g}"] + r.split(",")[1:]) for r in lines[head + 1:]]
    (tmp_path / "mine.toml").write_text(toml)
    (tmp_path / "mine.csv").write_text("\n".join(lines[:head + 1] + body) + "\n")
    with pytest.raises(DatasetError, match=r"column 't' starts at 10, not 0"):
        load_dataset(tmp_path / "mine.toml")


def test_epoch_seconds_are_refused_not_fitted(tmp_path):
    with pytest.raises(DatasetError, match=r"starts at 1700000000, not 0"):
        load_dataset(_pair(tmp_path, "spring-slider", 1.7e9))


def test_time_zero_shifts_the_column_and_show_names_it(tmp_path, capsys):
    (tmp_path / "a").mkdir()
    ref = load_dataset(_pair(tmp_path / "a", "spring-slider", 0.0))
    d = load_dataset(_pair(tmp_path, "spring-slider", 8105.381, time_zero="8105.381 s"))
    assert d.time_zero == 8105.381 and d.t[0] == 0.0
    assert np.allclose(d.t, ref.t, atol=1e-9)
    assert main(["datasets", "show", str(tmp_path / "mine.toml")]) == 0
    out = capsys.readouterr().out
    assert "t = 0 at 8105.381 s of the file's clock" in out
    assert f"noise:       {d.noise_kind} (" in out  # the kind, then what it means


def test_time_zero_after_the_first_sample_is_refused(tmp_path):
    with pytest.raises(DatasetError, match="time_zero = '5 us' is after the first time"):
        load_dataset(_pair(tmp_path, "impact", 0.0, time_zero="5 us"))


def test_a_first_sample_after_zero_is_accepted_when_declared(tmp_path):
    d = load_dataset(_pair(tmp_path, "impact", 10.0, time_zero="0 us"))
    assert d.t[0] == pytest.approx(10e-6)
