"""docs/guides/raw-records.md runs as written: its script makes the record, and the import prints the table
the guide shows (the guide's numbers are what the command gives)."""
from __future__ import annotations

import re
from pathlib import Path

from frictionlab.cli import main

GUIDE = Path(__file__).parents[1] / "docs" / "guides" / "raw-records.md"


def blocks(lang: str) -> list[str]:
    return re.findall(rf"```{lang}\n(.*?)```", GUIDE.read_text(encoding="utf-8"), re.S)


def test_the_guide_record_imports_as_the_guide_shows(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    exec(blocks("python")[0], {})
    (tmp_path / "data").mkdir()
    assert main(["datasets", "import", "velstep", "experiment.txt", "--name", "exp", "--out", "data/"]) == 0
    printed = capsys.readouterr().out.splitlines()
    shown = next(b for b in blocks("text") if b.startswith("experiment.txt:")).splitlines()
    assert printed == shown
    assert main(["datasets", "import", "velstep", "experiment.txt", "--name", "exp-all", "--joint", "--out",
                 "data/"]) == 0
    assert main(["datasets", "show", "data/exp-all.toml"]) == 0
    capsys.readouterr()
    assert main(["datasets", "import", "velstep", "experiment.txt", "--name", "exp", "--steps", "2", "--out",
                 "data/"]) == 2
    error = next(b for b in blocks("text") if b.startswith("frictionlab: error:")).strip()
    assert capsys.readouterr().err.strip().replace(f"{tmp_path}/", "") == error  # the record named by its full path
