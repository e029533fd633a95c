"""The bad-input corpus by class, tests/bad_inputs/by_class.toml and by_class_more.toml: cases by class (paths and links, names,
terminal and Markdown text, plugin numerics and time, API types, environment, signals), each with
what the user sees.

Every case, whatever its class: no traceback, and nothing a terminal would act on (ESC, BEL, other
control characters) on stdout or stderr. A case with status 2 has exactly one error line matching
``error`` and leaves its folder byte for byte as it was. The fields are described at the top of
by_class.toml.
"""
from __future__ import annotations

import builtins
import os
import re
import signal
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

import frictionlab as fl
from frictionlab import cli
from frictionlab.core import errors

from test_bad_inputs import ERROR_LINE, PROGRESS_LINE, clean_registry, prepare, snapshot  # noqa: F401 (a fixture)

CASES = [case for name in ("by_class.toml", "by_class_more.toml")
         for case in tomllib.loads((Path(__file__).parent / "bad_inputs" / name).read_text(encoding="utf-8"))["case"]]
CLASSES = ("paths", "names", "text", "plugins", "api", "environment", "signals")
FIELDS = {"id", "class", "sees", "base", "edit", "files", "argv", "python", "raises", "status", "error", "stdout",
          "stderr", "never", "report_never", "html_never", "written", "absent", "how", "env", "stdout_to", "close", "signal", "slow"}
ACTIVE = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f]")  # what a terminal acts on (\t and \n are text)


def params():
    return [pytest.param(c, id=c["id"], marks=[pytest.mark.slow] if c.get("slow") else []) for c in CASES]


def run_inprocess(argv, capsys):
    rc = cli.main(argv)
    out = capsys.readouterr()
    return rc, out.out, out.err


def run_subprocess(case, argv, tmp: Path):
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).parent), **case.get("env", {})}
    cmd = [sys.executable, "-c", "import sys; from frictionlab.cli import main; sys.exit(main(sys.argv[1:]))", *argv]
    stdout = open(os.devnull if case.get("stdout_to") != "full" else "/dev/full", "wb") \
        if case.get("stdout_to") else subprocess.PIPE
    close = case.get("close")
    closer = (lambda: os.close(2)) if close == "stderr" else (lambda: os.close(1)) if close == "stdout" else None
    if close == "stdout":
        stdout = None
    sig = case.get("signal")
    proc = subprocess.Popen(cmd, cwd=tmp, env=env, stdout=stdout, stderr=None if close == "stderr" else subprocess.PIPE,
                            preexec_fn=closer, text=True, errors="backslashreplace")
    err_lines = []
    if sig:  # send the signal once stderr shows the stage
        for line in proc.stderr:
            err_lines.append(line)
            if re.search(sig["when"], line):
                proc.send_signal(getattr(signal, "SIG" + sig["send"]))
                break
    try:
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    if not isinstance(stdout, int) and stdout is not None:
        stdout.close()
    return proc.returncode, out or "", "".join(err_lines) + (err or "")


def run_python(case, tmp: Path):
    namespace = {"fl": fl, "tmp": tmp, "Path": Path}
    raises = case.get("raises")
    if raises is None:
        exec(case["python"], namespace)
        return
    kind = getattr(builtins, raises, None) or getattr(errors, raises)
    with pytest.raises(kind) as info:
        exec(case["python"], namespace)
    assert type(info.value).__name__ != "AttributeError"
    msg = str(info.value)
    assert "\n" not in msg and re.search(case["error"], msg), f"{msg!r} does not match {case['error']!r}"


@pytest.mark.parametrize("case", params())
def test_case(case, tmp_path, capsys, monkeypatch, clean_registry):
    assert set(case) <= FIELDS and case["class"] in CLASSES and case["sees"], case["id"]
    run_case(case, tmp_path, capsys, monkeypatch)


def run_case(case, tmp_path, capsys, monkeypatch, refusal_writes_nothing: bool = False):
    """Prepare the case folder, run the case (its Python, or its command line in this process or a subprocess)
    and check what it did; with ``refusal_writes_nothing`` a Python case that raises leaves the folder as it was."""
    argv = prepare(case, tmp_path, case.get("argv", []))
    before = snapshot(tmp_path)
    monkeypatch.chdir(tmp_path)
    if "python" in case:
        run_python(case, tmp_path)
        if refusal_writes_nothing and case.get("raises"):
            assert snapshot(tmp_path) == before, "the case folder changed although the call was refused"
        return
    if case.get("how") == "subprocess" or any(k in case for k in ("env", "stdout_to", "close", "signal")):
        rc, out, err = run_subprocess(case, argv, tmp_path)
    else:
        rc, out, err = run_inprocess(argv, capsys)
    check(case, rc, out, err, before, tmp_path)


def check(case, rc, out, err, before, tmp: Path):
    status = case.get("status", 2)
    shown = f"exit {rc}\nstdout:\n{out[-2000:]}\nstderr:\n{err[-2000:]}"
    assert rc == status, shown
    assert "Traceback" not in err, shown
    assert not ACTIVE.search(out) and not ACTIVE.search(err.replace("\r", "")), f"control characters reached the terminal: {shown!r}"
    for rx in case.get("never", []):
        assert not re.search(rx, out + err), f"{rx!r} was shown:\n{shown}"
    if status == 2 and not case.get("signal") and case.get("close") != "stderr":
        lines = [x for x in err.splitlines() if x.strip() and not x.startswith("warning: ") and not PROGRESS_LINE.match(x)]
        assert len(lines) == 1 and ERROR_LINE.match(lines[0]), shown
        assert re.search(case["error"], lines[0]), f"{lines[0]!r} does not match {case['error']!r}"
    for key, text in (("stdout", out), ("stderr", err)):
        if key in case:
            assert re.search(case[key], text), f"{case[key]!r} not in {key}:\n{shown}"
    for rel in case.get("written", []):
        assert (tmp / rel).exists(), f"{rel} was not written:\n{shown}"
    for rel in case.get("absent", []):
        assert not os.path.lexists(tmp / rel), f"{rel} exists:\n{shown}"
    for key, name in (("report_never", "report.md"), ("html_never", "report.html")):
        text = (tmp / "out" / name).read_text(encoding="utf-8") if case.get(key) else ""
        for rx in case.get(key, []):
            assert not re.search(rx, text), f"{name} holds {rx!r}"
    if status != 0 and not case.get("written"):  # a run that failed or was stopped leaves the folder as it was
        assert snapshot(tmp) == before, f"the case folder changed:\n{shown}"


def test_corpus_by_class_counts():
    """At least 80 cases, every class represented, ids unique."""
    ids = [c["id"] for c in CASES]
    assert len(ids) == len(set(ids)) and len(ids) >= 80
    assert {c["class"] for c in CASES} == set(CLASSES)
