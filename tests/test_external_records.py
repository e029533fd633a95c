"""Measured records under a third party's license are not committed: listed by name and checksum, imported
from a raw-data folder when someone placed them there, and otherwise refused with where to put them."""
from __future__ import annotations

import hashlib
import sys
from pathlib import Path

import pytest

from frictionlab.core.errors import DatasetError
from frictionlab.io import external
from frictionlab.io.dataset import load_dataset

sys.path.insert(0, str(Path(__file__).parent))
from test_velstep_import import _record  # noqa: E402  (a record the test makes, in the raw format)


@pytest.fixture
def placed(tmp_path, monkeypatch):
    raw = tmp_path / "raw" / "lab"
    raw.mkdir(parents=True)
    _record(raw / "step.txt")
    sha = hashlib.sha256((raw / "step.txt").read_bytes()).hexdigest()
    spec = dict(format="velstep", file="lab/step.txt", sha256=sha, source="a test record", license="MIT",
                citation="nobody")
    monkeypatch.setattr(external, "RECORDS", {"lab-step": spec})
    monkeypatch.setenv("FRICTIONLAB_RAW_DATA", str(tmp_path / "raw"))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    return raw / "step.txt"


def test_a_placed_record_loads_by_name_as_measured(placed, tmp_path):
    d = load_dataset("lab-step")
    assert d.provenance.kind == "measured" and d.provenance.license == "MIT"
    assert external.present() == ["lab-step"]
    assert str(d.path).startswith(str(tmp_path / "cache"))
    assert load_dataset("lab-step").path == d.path  # imported once


def test_an_absent_or_altered_record_says_where_to_place_it(placed):
    placed.write_text(placed.read_text().replace("30.", "31.", 1))  # not the record the checksum names
    with pytest.raises(DatasetError, match=r"dataset 'lab-step' is a measured record not held in the repository "
                                           r"\(MIT license, a test record\): place the file at .*lab/step.txt"):
        load_dataset("lab-step")
    assert external.present() == []


def test_the_steadystate_records_are_named_with_their_license_and_checksum():
    for name, spec in external.RECORDS.items():
        assert name.split("-")[0] in ("sepiolite", "basalt") and spec["license"] == "MIT" and len(spec["sha256"]) == 64
        assert "10.1130/GES02739.1" in spec["citation"]


def test_a_record_with_a_stated_stiffness_start_is_imported_with_it(placed, monkeypatch):
    spec = dict(external.RECORDS["lab-step"], stiffness=2e3)
    monkeypatch.setattr(external, "RECORDS", {"lab-step": spec})
    d = load_dataset("lab-step")
    assert d.scene.spring.stiffness == pytest.approx(2e3)
    assert "--stiffness '0.002 1/um'" in d.provenance.command
    assert "a start; fit it with --free spring.stiffness" in d.path.read_text()
