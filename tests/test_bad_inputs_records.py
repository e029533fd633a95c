"""The bad-input corpus of raw laboratory records and of the measured-record cache, tests/bad_inputs/records.toml
(its fields are described at its top): each case run through the command line in its own folder.

Every case: no traceback, and no temporary file the run wrote named on stdout or stderr. A case with status 2
has exactly one error line matching ``error`` and leaves its folder byte for byte as it was."""
from __future__ import annotations

import hashlib
import os
import re
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

from frictionlab import cli
from frictionlab.io import external

from test_bad_inputs import ERROR_LINE, snapshot

CASES = [case for name in ("records.toml", "records_shapes.toml")
         for case in tomllib.loads((Path(__file__).parent / "bad_inputs" / name).read_text(encoding="utf-8"))["case"]]
CLASSES = ("raw", "options", "cache")
FIELDS = {"id", "class", "sees", "record", "lines", "text", "text_python", "encoding", "sep", "fifo", "rename", "files",
          "prime", "mutate", "env", "nopasswd", "tmpfs", "argv", "status", "error", "stdout", "stderr", "never",
          "written", "absent", "unchanged", "empty", "no_files_below"}
HEADER = "Time(s)\tDispl(microns)\tFriction\tEffectiveNormalstress(MPa)"
#: Names of the temporary files and folders an import or the cache writes: never shown to the user.
TEMPORARY = re.compile(r"\.import\.\w+\.tmp|\.lab-step\.\w+\.|/tmp\w*\.(csv|toml)\b|\.tmp\b")


def params():
    return [pytest.param(c, id=c["id"]) for c in CASES]


def write_record(case: dict, path: Path) -> None:
    """The case's record in the raw format (four columns under the usual header, separated by ``sep``: a tab
    unless the case says otherwise), in the case's ``encoding`` (UTF-8 unless it says otherwise)."""
    if "text" in case:
        path.write_bytes(case["text"].encode(case.get("encoding", "utf-8")))
        return
    rng = np.random.default_rng(0)
    space = {}
    if "text_python" in case:  # t and x; optionally noise (um, default 0.05), quantum (um), mu, sn, fmt, header
        exec(case["text_python"], space)
        t, x = space["t"], space["x"] + rng.normal(0, space.get("noise", 0.05), space["t"].size)
        if "quantum" in space:
            x = np.round(x / space["quantum"]) * space["quantum"]
    else:
        r = case["record"]
        n, dt = r["rows"], r["dt"]
        t = r.get("t0", 0.0) + np.arange(n) * dt
        if "first_dt" in r:
            t[:3] = np.arange(3) * r["first_dt"]
        edges = [t[0], *r.get("knots", []), np.inf]
        x = sum(v * np.clip(t - a, 0.0, b - a) for a, b, v in zip(edges[:-1], edges[1:], r["velocities"]))
        x = x + rng.normal(0, r.get("noise", 0.05), n)
        for when, size in r.get("jumps", []):
            x[t >= when] += size
    mu, sn = 0.6 + rng.normal(0, 5e-4, t.size), 30 + rng.normal(0, 0.01, t.size)
    mu, sn = np.broadcast_to(space.get("mu", mu), t.shape), np.broadcast_to(space.get("sn", sn), t.shape)
    sep, fx = case.get("sep", "\t"), space.get("fmt", "%.6f")
    row = f"%.10g{sep}{fx}{sep}%.6f{sep}%.6f\n"  # every row formatted in one call: a long record is written in seconds
    body = (row * t.size) % tuple(np.column_stack([t, x, mu, sn]).ravel().tolist())
    lines = [space.get("header", HEADER).replace("\t", sep)] + body.split("\n")[:-1]
    for no, text in case.get("lines", []):
        lines[no - 1] = text
    path.write_bytes(("\n".join(lines) + "\n").encode(case.get("encoding", "utf-8")))


@pytest.fixture
def tmpfs(tmp_path):
    """Mount a small tmpfs at tmp/full when a case asks for one (skip, with the reason, when it cannot be)."""
    mounted = []

    def mount(size: str) -> None:
        (tmp_path / "full").mkdir()
        out = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(tmp_path / "full")],
                             capture_output=True, text=True)
        if out.returncode != 0:
            pytest.skip(f"cannot mount a {size} tmpfs for a full disk ({out.stderr.strip() or 'not permitted'})")
        mounted.append(tmp_path / "full")

    yield mount
    for m in mounted:
        subprocess.run(["umount", str(m)], check=False)


def cache_folder(tmp: Path) -> Path:
    key = external.RECORDS["lab-step"]["sha256"][:16]
    return tmp / "cache" / "frictionlab" / "external" / key


def prepare(case: dict, tmp: Path, monkeypatch, tmpfs) -> list[str]:
    """Build the case folder (record, placed record, cache, mutations, environment); argv with placeholders filled."""
    fill = {"{tmp}": str(tmp)}

    def filled(text: str) -> str:
        for k, v in fill.items():
            text = text.replace(k, v)
        return text

    if case.get("tmpfs"):
        tmpfs(case["tmpfs"])
    if case.get("fifo"):
        os.mkfifo(tmp / "rec.txt")
    elif case["class"] == "cache":
        (tmp / "raw" / "lab").mkdir(parents=True)
        write_record({"record": {"rows": 3000, "dt": 0.1, "knots": [150.0], "velocities": [1.0, 10.0]}},
                     tmp / "raw" / "lab" / "step.txt")
        data = (tmp / "raw" / "lab" / "step.txt").read_bytes()
        monkeypatch.setattr(external, "RECORDS", {"lab-step": dict(
            format="velstep", file="lab/step.txt", size=len(data), sha256=hashlib.sha256(data).hexdigest(),
            source="a test record", license="MIT", citation="nobody")})
        monkeypatch.setenv("FRICTIONLAB_RAW_DATA", str(tmp / "raw"))
        monkeypatch.setenv("XDG_CACHE_HOME", str(tmp / "cache"))
        fill["{cache}"] = str(cache_folder(tmp))
    elif "record" in case or "text" in case or "text_python" in case:
        write_record(case, tmp / case.get("rename", "rec.txt"))
    for f in case.get("files", []):
        (tmp / f["path"]).write_text(f["text"])
    if case.get("prime"):
        assert cli.main(["datasets", "show", "lab-step"]) == 0
    for m in case.get("mutate", []):
        path = Path(filled(m["path"]))
        path = path if path.is_absolute() else tmp / path
        if m["do"] == "replace":
            text = path.read_text()
            assert m["old"] in text, (case["id"], m)
            path.write_text(text.replace(m["old"], m["new"], 1))
        elif m["do"] == "delete":
            shutil.rmtree(path) if path.is_dir() and not path.is_symlink() else path.unlink()
        elif m["do"] == "symlink":
            path.symlink_to(filled(m["target"]))
        elif m["do"] == "truncate":
            path.write_bytes(path.read_bytes()[:m["bytes"]])
        elif m["do"] == "mkdir":
            path.mkdir()
        elif m["do"] == "write":
            path.write_text(m["text"])
    for key, value in case.get("env", {}).items():
        if value:
            monkeypatch.setenv(key, filled(value))
        else:
            monkeypatch.delenv(key, raising=False)
    monkeypatch.chdir(tmp)
    return [filled(a) for a in case["argv"]]


#: A cache case runs `frictionlab ARGV` in a new process with the test record placed as "lab-step".
RUNNER = """
import sys
from frictionlab.io import external
external.RECORDS = {records!r}
if {nopasswd!r}:
    import pwd

    def nobody(uid):
        raise KeyError(f"getpwuid(): uid not found: {{uid}}")

    pwd.getpwuid = nobody
from frictionlab.cli import main
sys.exit(main(sys.argv[1:]))
"""


def run_subprocess(case: dict, argv: list[str], tmp: Path):
    code = RUNNER.format(records=external.RECORDS, nopasswd=bool(case.get("nopasswd")))
    out = subprocess.run([sys.executable, "-c", code, *argv], cwd=tmp, env=dict(os.environ), capture_output=True,
                         text=True, timeout=300)
    return out.returncode, out.stdout, out.stderr


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.mark.parametrize("case", params())
def test_case(case, tmp_path, capsys, monkeypatch, tmpfs):
    assert set(case) <= FIELDS and case["class"] in CLASSES and case["sees"], case["id"]
    argv = prepare(case, tmp_path, monkeypatch, tmpfs)
    capsys.readouterr()
    kept = {p: digest(tmp_path / p) for p in case.get("unchanged", [])}
    before = snapshot(tmp_path)
    if case["class"] == "cache":  # as a user runs it: notes on stderr, the environment of the case
        rc, out, err = run_subprocess(case, argv, tmp_path)
    else:
        rc = cli.main(argv)
        out, err = capsys.readouterr()
    shown = f"exit {rc}\nstdout:\n{out[-3000:]}\nstderr:\n{err[-3000:]}"
    status = case.get("status", 2)
    assert rc == status, shown
    assert "Traceback" not in err and not TEMPORARY.search(out + err), shown
    for rx in case.get("never", []):
        assert not re.search(rx, out + err), f"{rx!r} was shown:\n{shown}"
    if status == 2:
        lines = [x for x in err.splitlines() if x.strip() and not x.startswith("warning: ")]
        assert len(lines) == 1 and ERROR_LINE.match(lines[0]), shown
        assert re.search(case["error"], lines[0]), f"{lines[0]!r} does not match {case['error']!r}"
        assert snapshot(tmp_path) == before, "the case folder changed"
    for key, text in (("stdout", out), ("stderr", err)):
        if key in case:
            assert re.search(case[key], text), f"{case[key]!r} not in {key}:\n{shown}"
    for p in case.get("written", []):
        assert (tmp_path / p).exists(), f"{p} was not written:\n{shown}"
    for p in case.get("absent", []):
        assert not (tmp_path / p).exists(), f"{p} exists:\n{shown}"
    for p, h in kept.items():
        assert digest(tmp_path / p) == h, f"{p} changed"
    for p in case.get("empty", []):
        assert not any((tmp_path / p).iterdir()), f"{p} is not empty"
    if "no_files_below" in case:
        assert not [p for p in (tmp_path / case["no_files_below"]).rglob("*") if not p.is_dir()]
