"""A pytest plugin: the CPU time of each test, its own process's and its child processes' (a command the test ran),
and at the end the files and the tests that cost the most CPU. ``--durations`` gives wall time, which two
parallel workers on two cores blur; CPU seconds add up to what the suite costs.

    PYTHONPATH=benchmarks python -m pytest -p pytest_cpu [--cpu-top 30] [--cpu-log FILE]

Each worker appends one JSON line a test to a file in a temporary folder the main process made (named to the
workers by the environment variable PYTEST_CPU_DIR); the main process prints the summary and removes the folder.
"""
from __future__ import annotations

import json
import os
import resource
import shutil
import tempfile
import time
from collections import Counter
from pathlib import Path

import pytest


def pytest_addoption(parser):
    parser.addoption("--cpu-top", type=int, default=30, help="tests and files listed by CPU time (pytest_cpu)")
    parser.addoption("--cpu-log", default=None, help="also keep the JSON line of each test in this file (pytest_cpu)")


def _cpu() -> tuple[float, float]:
    me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime, kids.ru_utime + kids.ru_stime


def _log() -> Path:
    return Path(os.environ["PYTEST_CPU_DIR"]) / "cpu-per-test.jsonl"


def pytest_configure(config):
    if not hasattr(config, "workerinput"):  # the main process: xdist's workers inherit the variable
        os.environ["PYTEST_CPU_DIR"] = tempfile.mkdtemp(prefix="pytest-cpu-")


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    own, kids = _cpu()
    wall = time.perf_counter()
    yield
    own2, kids2 = _cpu()
    with open(_log(), "a", encoding="utf-8") as fh:
        fh.write(json.dumps({"id": item.nodeid, "own": own2 - own, "children": kids2 - kids,
                             "wall": time.perf_counter() - wall}) + "\n")


def pytest_terminal_summary(terminalreporter, config):
    if hasattr(config, "workerinput"):
        return
    log = _log()
    try:
        rows = [json.loads(line) for line in log.read_text(encoding="utf-8").splitlines() if line.strip()]
    except FileNotFoundError:
        rows = []
    if config.getoption("cpu_log"):
        shutil.copyfile(log, config.getoption("cpu_log"))
    shutil.rmtree(log.parent, ignore_errors=True)
    if not rows:
        return
    top = config.getoption("cpu_top")
    total = sum(r["own"] + r["children"] for r in rows)
    by_file = Counter()
    for r in rows:
        by_file[r["id"].split("::")[0]] += r["own"] + r["children"]
    tr = terminalreporter
    tr.section(f"CPU time: {total:.1f} s in {len(rows)} tests (own + child processes)")
    for name, cpu in by_file.most_common(top):
        tr.write_line(f"{cpu:8.1f} s  {name}")
    tr.write_line("")
    for r in sorted(rows, key=lambda r: -(r["own"] + r["children"]))[:top]:
        tr.write_line(f"{r['own'] + r['children']:8.1f} s  (children {r['children']:.1f}, wall {r['wall']:.1f})  {r['id']}")
