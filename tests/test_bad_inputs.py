"""The bad-input corpus, tests/bad_inputs/cases.toml, run through the command line.

Every case must give exit status 2, exactly one error line that matches its regex and names
the file, field or parameter, no traceback (unless --debug), and no output: the case folder
(the working directory of the run) is byte-for-byte what it was before, so no --out file or
folder, no temporary leftovers, and an existing folder left untouched.

Loader cases (no argv) run as `datasets show`, through the library, and through every command
that reads data (simulate, fit, compare) as soon as that command is registered.
"""
from __future__ import annotations

import hashlib
import importlib.util
import os
import re
import shutil
import stat
import sys
import tomllib
from pathlib import Path

import pytest

import frictionlab as fl
from frictionlab import cli
from frictionlab.core.errors import FrictionLabError
from frictionlab.io.dataset import builtin_dir
from frictionlab.physics import registry

CASES_FILE = Path(__file__).parent / "bad_inputs" / "cases.toml"
CASES = tomllib.loads(CASES_FILE.read_text(encoding="utf-8"))["case"]

#: How a loader case (a broken dataset) is handed to each command that reads data.
LOADER_ARGV = {
    "datasets": ["datasets", "show", "{data}"],
    "simulate": ["simulate", "coulomb", "{data}", "--out", "{out}"],
    "fit": ["fit", "coulomb", "{data}"],
    "compare": ["compare", "--laws", "coulomb", "--data", "{data}", "--out", "{out}"],
}

ERROR_LINE = re.compile(r"^frictionlab( [\w-]+)?: error: ")


def command_of(argv: list[str]) -> str | None:
    """The subcommand an argv names (skipping the global options)."""
    it = iter(argv)
    for tok in it:
        if tok == "--load":
            next(it, None)
        elif not tok.startswith("-"):
            return tok
    return None


def registered(command: str) -> bool:
    return importlib.util.find_spec(f"frictionlab.commands.{command}") is not None


def runs() -> list:
    out = []
    for case in CASES:
        if "argv" in case:
            out.append(pytest.param(case, case["argv"], id=case["id"]))
        else:
            for name, argv in LOADER_ARGV.items():
                out.append(pytest.param(case, argv, id=f"{case['id']}[{name}]"))
    return out


# -- preparing a case ------------------------------------------------------------------
def prepare(case: dict, tmp: Path, argv: list[str]) -> list[str]:
    """Build the case folder and return argv with its placeholders filled in."""
    base = case.get("base")
    if base:
        for ext in ("toml", "csv"):
            shutil.copy(builtin_dir() / f"{base}.{ext}", tmp / f"d.{ext}")
    out = tmp / ("out.csv" if command_of(argv) == "simulate" else "out")
    fill = {"{tmp}": str(tmp), "{data}": str(tmp / "d.toml"), "{out}": str(out),
            "{existing}": str(tmp / "existing"), "{notdir}": str(tmp / "a-file"), "{file}": str(tmp / "a-file")}

    def filled(text: str) -> str:
        for k, v in fill.items():
            text = text.replace(k, v)
        return text

    for e in case.get("edit", []):
        path = tmp / f"d.{e['file']}"
        if e.get("delete"):
            path.unlink()
        elif e.get("bom"):
            path.write_bytes(b"\xef\xbb\xbf" + path.read_bytes())
        elif "content" in e:
            path.write_bytes(e["content"].encode(e.get("encoding", "utf-8")))
        else:
            text = path.read_text(encoding="utf-8")
            assert e["old"] in text, f"case {case['id']}: {e['old']!r} no longer occurs in {base}.{e['file']}"
            path.write_text(text.replace(e["old"], e["new"] * e.get("times", 1), 1), encoding="utf-8")
    for f in case.get("files", []):
        path = tmp / f["path"]
        kind = f.get("kind", "file")
        if kind == "fifo":
            os.mkfifo(path)
        elif kind == "symlink":
            path.symlink_to(filled(f["target"]))
        elif kind == "hardlink":
            os.link(filled(f["target"]), path)
        elif kind == "dir":
            path.mkdir()
        else:
            path.write_text(f["content"], encoding="utf-8")
    (tmp / "existing").mkdir()
    (tmp / "existing" / "keep.txt").write_text("an earlier report\n")
    (tmp / "a-file").write_text("a regular file, so nothing can be created below it\n")
    return [filled(a) for a in argv]


def snapshot(folder: Path) -> dict[str, str]:
    """Every path below ``folder`` with a hash of its content ('dir' for folders; a link or special
    file by what it is, never opened: a FIFO would block, a link may lead anywhere)."""
    out = {}
    for p in sorted(folder.rglob("*")):
        mode = p.lstat().st_mode
        if stat.S_ISLNK(mode):
            value = f"link to {os.readlink(p)}"
        elif stat.S_ISDIR(mode):
            value = "dir"
        elif not stat.S_ISREG(mode):
            value = f"special {stat.S_IFMT(mode):o}"
        else:
            value = hashlib.sha256(p.read_bytes()).hexdigest()
        out[str(p.relative_to(folder))] = value
    return out


#: Progress lines on stderr (frictionlab.core.progress, when stderr is not a terminal) are not error lines.
PROGRESS_LINE = re.compile(r"^\d{4}-\d\d-\d\d \d\d:\d\d:\d\d [\w-]+: ")


def check(case: dict, rc: int, stderr: str, before: dict, tmp: Path) -> None:
    assert "Traceback" not in stderr, stderr
    lines = [line for line in stderr.splitlines() if line.strip() and not line.startswith("warning: ")
             and not PROGRESS_LINE.match(line)]
    assert len(lines) == 1, f"expected one error line, got:\n{stderr}"
    line = lines[0]
    assert ERROR_LINE.match(line), line
    assert re.search(case["error"], line), f"{line!r} does not match {case['error']!r}"
    assert rc == 2, f"exit status {rc}: {line}"
    assert snapshot(tmp) == before, "output was written (or the case folder changed) although the run failed"


@pytest.fixture
def clean_registry():
    """Undo laws that --load registered at run time, so cases stay independent."""
    before = set(fl.available_laws())
    modules = set(sys.modules)
    yield
    for name in set(fl.available_laws()) - before:
        registry.unregister_law(name)
    for name in set(sys.modules) - modules:
        if name.startswith("frictionlab_user_"):
            del sys.modules[name]


# -- the corpus ----------------------------------------------------------------------------
@pytest.mark.parametrize("case, argv", runs())
def test_bad_input_is_one_line_exit_2_and_writes_nothing(case, argv, tmp_path, capsys, monkeypatch, clean_registry):
    command = command_of(argv)
    if command in cli.COMMANDS and not registered(command):
        pytest.skip(f"subcommand '{command}' is not registered yet (lands from another branch)")
    argv = prepare(case, tmp_path, argv)
    before = snapshot(tmp_path)
    monkeypatch.chdir(tmp_path)  # anything written relative to the working directory shows up
    rc = cli.main(argv)
    check(case, rc, capsys.readouterr().err, before, tmp_path)


@pytest.mark.parametrize("case", [c for c in CASES if "argv" not in c], ids=lambda c: c["id"])
def test_loader_case_through_the_library(case, tmp_path):
    prepare(case, tmp_path, [])
    with pytest.raises(FrictionLabError) as info:
        fl.load_dataset(tmp_path / "d.toml")
    msg = str(info.value)
    assert "\n" not in msg
    assert re.search(case["error"], msg), f"{msg!r} does not match {case['error']!r}"


@pytest.mark.parametrize("case", [c for c in CASES if c.get("subprocess")], ids=lambda c: c["id"])
def test_no_traceback_reaches_the_terminal(case, tmp_path, run_cli):
    argv = case.get("argv", LOADER_ARGV["datasets"])
    command = command_of(argv)
    if command in cli.COMMANDS and not registered(command):
        pytest.skip(f"subcommand '{command}' is not registered yet")
    argv = prepare(case, tmp_path, argv)
    before = snapshot(tmp_path)
    out = run_cli(*argv, cwd=tmp_path)
    check(case, out.returncode, out.stderr, before, tmp_path)
    assert out.stderr.count("\n") == 1  # nothing else at all on the terminal's error stream


def test_debug_shows_the_traceback(tmp_path, monkeypatch):
    case = next(c for c in CASES if c["id"] == "mass-in-metres")
    argv = prepare(case, tmp_path, LOADER_ARGV["datasets"])
    monkeypatch.chdir(tmp_path)
    with pytest.raises(FrictionLabError, match=case["error"]):
        cli.main(["--debug", *argv])


# -- the corpus itself ---------------------------------------------------------------------
def test_corpus_is_well_formed():
    ids = [c["id"] for c in CASES]
    assert len(ids) == len(set(ids)), "duplicate case ids"
    assert len(CASES) >= 30
    for c in CASES:
        assert set(c) <= {"id", "base", "edit", "files", "argv", "error", "subprocess"}, c["id"]
        assert "base" in c or "argv" in c, c["id"]
        re.compile(c["error"])
        assert c.get("edit") or "argv" in c, f"{c['id']}: a loader case needs an edit"


@pytest.mark.parametrize("base", sorted({c["base"] for c in CASES if "base" in c}))
def test_every_base_loads_cleanly(base, tmp_path):
    """The errors come from the edits: the untouched copies load."""
    for ext in ("toml", "csv"):
        shutil.copy(builtin_dir() / f"{base}.{ext}", tmp_path / f"d.{ext}")
    assert len(fl.load_dataset(tmp_path / "d.toml")) > 2
