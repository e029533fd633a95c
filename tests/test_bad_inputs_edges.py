"""The bad-input corpus of what is read at the edges, tests/bad_inputs/edges.toml: quantity strings read exactly,
the equivalence test's family of pairs and its margin, scheduler addresses, the library's own arguments (axes,
mappings, datasets changed after loading), report folders rewritten with --force, and the messages at the
physical edges of the spring-slider.

Every case is checked as the other corpora are (``test_bad_inputs_by_class.check``): its exit status, no
traceback, nothing a terminal acts on, and with status 2 exactly one error line matching ``error`` and the case
folder byte for byte as it was. A ``python`` case runs in the test's process; with ``raises`` its one-line
message must match ``error``. The fields are those of by_class.toml, with the classes below.
"""
from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

from test_bad_inputs import clean_registry  # noqa: F401 (a fixture)
from test_bad_inputs_by_class import run_case

CASES = tomllib.loads((Path(__file__).parent / "bad_inputs" / "edges.toml").read_text(encoding="utf-8"))["case"]
CLASSES = ("quantities", "family", "addresses", "arguments", "force", "physics")
FIELDS = {"id", "class", "sees", "base", "edit", "files", "argv", "python", "raises", "status", "error", "stdout",
          "stderr", "never", "written", "absent", "how", "slow"}


def params():
    return [pytest.param(c, id=c["id"], marks=[pytest.mark.slow] if c.get("slow") else []) for c in CASES]


@pytest.mark.parametrize("case", params())
def test_case(case, tmp_path, capsys, monkeypatch, clean_registry):
    assert set(case) <= FIELDS and case["class"] in CLASSES and case["sees"], case["id"]
    run_case(case, tmp_path, capsys, monkeypatch, refusal_writes_nothing=True)


def test_edges_corpus_counts():
    """At least 48 cases, every class represented, ids unique."""
    ids = [c["id"] for c in CASES]
    assert len(ids) == len(set(ids)) and len(ids) >= 48
    assert {c["class"] for c in CASES} == set(CLASSES)
