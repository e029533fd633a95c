"""Measured records under a third party's license are not committed: listed by name, size and checksum,
imported from a raw-data folder when someone placed them there into a cache that is checked at each load,
and otherwise refused with where to put them (absent, another checksum, truncated)."""
from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

import pytest

from frictionlab.core.errors import DatasetError
from frictionlab.io import external
from frictionlab.io.dataset import available_names, load_dataset

sys.path.insert(0, str(Path(__file__).parent))
from test_velstep_import import _record  # noqa: E402  (a record the test makes, in the raw format)


@pytest.fixture
def placed(tmp_path, monkeypatch):
    raw = tmp_path / "raw" / "lab"
    raw.mkdir(parents=True)
    _record(raw / "step.txt")
    data = (raw / "step.txt").read_bytes()
    spec = dict(format="velstep", file="lab/step.txt", size=len(data), sha256=hashlib.sha256(data).hexdigest(),
                source="a test record", license="MIT", citation="nobody")
    monkeypatch.setattr(external, "RECORDS", {"lab-step": spec})
    monkeypatch.setenv("FRICTIONLAB_RAW_DATA", str(tmp_path / "raw"))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    return raw / "step.txt"


def cached(tmp_path, ext: str) -> Path:
    (path,) = (tmp_path / "cache" / "frictionlab" / "external").glob(f"*/lab-step.{ext}")
    return path


def test_a_placed_record_loads_by_name_as_measured_and_is_listed(placed, tmp_path):
    d = load_dataset("lab-step")
    assert d.provenance.kind == "measured" and d.provenance.license == "MIT" and d.kind == "spring-slider"
    assert external.present() == ["lab-step"] and available_names()[-1] == "lab-step"
    assert str(d.path).startswith(str(tmp_path / "cache" / "frictionlab" / "external"))
    manifest = json.loads(cached(tmp_path, "json").read_text())
    assert manifest["record"] == external.RECORDS["lab-step"]["sha256"]
    for ext in ("csv", "toml"):
        assert manifest[ext] == hashlib.sha256(cached(tmp_path, ext).read_bytes()).hexdigest()
    assert load_dataset("lab-step").path == d.path  # from the cache


@pytest.mark.parametrize("ext, edit", [("csv", lambda s: s.replace(",0.5", ",0.6", 1)),
                                       ("toml", lambda s: s.replace('"0 s"', '"1 s"'))])
def test_an_edited_cache_is_imported_again_with_a_note(placed, tmp_path, ext, edit):
    first = load_dataset("lab-step")
    path = cached(tmp_path, ext)
    path.write_text(edit(path.read_text()))
    with pytest.warns(UserWarning, match=rf"the cached import of lab-step in .* has a {ext.upper()} that differs from "
                                         "its checksum \\(edited\\?\\): imported again from .*step.txt"):
        again = load_dataset("lab-step")
    assert (again.y == first.y).all() and again.scene.spring.times == first.scene.spring.times


def test_a_cache_of_another_importer_or_without_manifest_is_imported_again(placed, tmp_path):
    load_dataset("lab-step")
    m = cached(tmp_path, "json")
    m.write_text(m.read_text().replace(external.IMPORTER, "velstep-0"))
    with pytest.warns(UserWarning, match="was made by another version of the importer"):
        load_dataset("lab-step")
    m.unlink()
    with pytest.warns(UserWarning, match="has no readable manifest"):
        load_dataset("lab-step")
    assert json.loads(m.read_text())["importer"] == external.IMPORTER


def test_a_planted_link_in_the_cache_is_replaced_never_followed(placed, tmp_path):
    load_dataset("lab-step")
    victim = tmp_path / "victim.csv"
    victim.write_text("keep me\n")
    csv = cached(tmp_path, "csv")
    csv.unlink()
    csv.symlink_to(victim)
    with pytest.warns(UserWarning, match="has lost its CSV"):
        d = load_dataset("lab-step")
    assert victim.read_text() == "keep me\n" and not csv.is_symlink() and len(d) == 7000


def test_a_cache_folder_that_is_a_link_or_a_file_is_not_used(placed, tmp_path):
    root = tmp_path / "cache" / "frictionlab"
    root.parent.mkdir()
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    root.symlink_to(elsewhere)
    with pytest.warns(UserWarning, match=r"cannot use the cache folder .*is a symbolic link.*: lab-step imported in "
                                         "memory"):
        d = load_dataset("lab-step")
    assert list(elsewhere.iterdir()) == [] and len(d) == 7000 and d.provenance.kind == "measured"


def test_a_relative_xdg_cache_home_is_ignored_with_a_note(placed, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("XDG_CACHE_HOME", "relcache")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    with pytest.warns(UserWarning, match="XDG_CACHE_HOME='relcache' is not an absolute path: ignored"):
        load_dataset("lab-step")
    assert not (tmp_path / "relcache").exists()
    assert list((tmp_path / "home" / ".cache" / "frictionlab" / "external").glob("*/lab-step.toml"))


def test_no_home_and_no_passwd_entry_imports_in_memory_with_a_note(placed, monkeypatch):
    """HOME unset and no passwd entry for the user: the record is imported in memory, with a note."""
    import pwd

    def nobody(uid):
        raise KeyError(f"getpwuid(): uid not found: {uid}")

    monkeypatch.delenv("HOME")
    monkeypatch.delenv("XDG_CACHE_HOME")
    monkeypatch.setattr(pwd, "getpwuid", nobody)
    with pytest.warns(UserWarning, match="no cache folder for measured records .*: imported in memory"):
        d = load_dataset("lab-step")
    assert len(d) == 7000 and d.provenance.kind == "measured" and d.path == placed


def test_an_absent_record_says_where_to_place_it(placed):
    placed.unlink()
    with pytest.raises(DatasetError, match=r"dataset 'lab-step' is a measured record not held in the repository "
                                           r"\(MIT license, a test record\): place the file at .*lab/step.txt"):
        load_dataset("lab-step")
    assert external.present() == []


def test_a_record_with_another_checksum_or_truncated_is_named_as_such(placed):
    data = placed.read_bytes()
    placed.write_bytes(data.replace(b"30.", b"31.", 1))
    with pytest.raises(DatasetError, match=r"dataset 'lab-step': the measured record is there but is not the one named: "
                                           r".*step.txt has another checksum \(SHA-256 [0-9a-f]{12}\.\.\., not"):
        load_dataset("lab-step")
    placed.write_bytes(data[:1000])
    with pytest.raises(DatasetError, match=rf"step.txt is truncated \(1000 of {len(data)} bytes\)"):
        load_dataset("lab-step")


def test_the_steadystate_records_are_named_with_their_license_size_and_checksum():
    for name, spec in external.RECORDS.items():
        assert name.split("-")[0] in ("sepiolite", "basalt") and spec["license"] == "MIT" and len(spec["sha256"]) == 64
        assert "10.1130/GES02739.1" in spec["citation"] and spec["size"] > 0 and "stiffness" not in spec
