"""What the repository ships speaks of the project only: no path of the machine it was written on, no
"round" or "pass" of work, no issue number and no dated diary entry, in any tracked text file (README,
docs, code and its comments and docstrings, report templates, tests, data sidecars). History belongs in
git and CHANGELOG.md.

The patterns are precise, so that ordinary words pass: "pass its fit tests", "bypass", "round-off",
"a round trip", "rounded", "each round of the batch loop", "a dataset named 2026-05-04".
"""
from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
MONTHS = "January|February|March|April|May|June|July|August|September|October|November|December"
WORDS = "one|two|three|four|five|six|seven|eight|nine|ten"
#: what is looked for, by what it would mean
PATTERNS = {
    "a round of work": re.compile(
        rf"\bround[ _-]?(?:\d+|{WORDS})\b|\b(?:this|last|next|previous|earlier|later|same) round\b(?![- ](?:off|trip))"
        rf"|\brounds? (?:ago|earlier|before this)\b|\b(?:{WORDS}) rounds\b", re.I),
    "a pass of work": re.compile(
        r"\b(?:first|second|third|fourth|fifth|sixth|seventh|eighth|ninth|tenth|this|last|previous|next|earlier)"
        r" pass\b(?! (?:of|through|over) the (?:data|grid|scenes|records?|loop))|\bpass(?:es)? that led\b", re.I),
    "an issue number": re.compile(r"\bissues? ?#?\d+\b", re.I),
    "a machine path": re.compile(r"/work/|/tmp/fresh|/home/\w|(?<![\w.~])/root/|/Users/\w"),
    "a dated entry": re.compile(rf"\b\d{{1,2}} (?:{MONTHS}),? 20\d\d\b|\b(?:{MONTHS}) \d{{0,2}},? ?20\d\d\b"),
}
#: files allowed to hold a match, each with the reason
ALLOWED = {
    "tests/test_shipped_text.py": "states the patterns and the cases that must (not) match",
}


def tracked_text_files() -> list[Path]:
    try:
        out = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True, timeout=60).stdout
    except (OSError, subprocess.SubprocessError):
        pytest.skip("not a git checkout (git ls-files failed): the tracked files are unknown")
    files = []
    for name in out.decode().split("\0"):
        path = ROOT / name
        if name and path.is_file() and name not in ALLOWED:
            try:
                path.read_text(encoding="utf-8")
            except UnicodeDecodeError:
                continue  # a binary file (a PNG)
            files.append(path)
    return files


def findings(text: str) -> list[tuple[int, str, str]]:
    """(line number, what, matched text) of every match in ``text``."""
    out = []
    for i, line in enumerate(text.splitlines(), 1):
        for what, pattern in PATTERNS.items():
            m = pattern.search(line)
            if m:
                out.append((i, what, m.group()))
    return out


def test_no_tracked_text_names_the_machine_or_the_history():
    bad = [f"{p.relative_to(ROOT)}:{i}: {what}: {hit!r}"
           for p in tracked_text_files() for i, what, hit in findings(p.read_text(encoding="utf-8"))]
    assert bad == []


@pytest.mark.parametrize("text", [
    "Fourth pass (24 November 2026): the fits", "this round's changes", "three rounds ago", "Round 4", "round four",
    "see issue 22", "Issue #31", "git clone . /tmp/fresh15", "the records at /work/shared/data", "/home/alice/x",
    "measured on 25 November 2026", "November 2026", "the passes that led here",
    "tests/bad_inputs/round3.toml",
])
def test_the_patterns_find_the_history(text):
    assert findings(text)


@pytest.mark.parametrize("text", [
    "the fits pass its fit tests", "bypass the cache", "round-off", "one round trip per task", "rounded to its error",
    "with the scenes still going in each round", "a timestamp 2026-11-23 01:02:03", "the second pass of the data",
    "rate-and-state (Marone 1998)", "Sci. Rep. 7, 40102 (2017)", "~/.cache", "run `pytest`, which must pass",
])
def test_the_patterns_let_ordinary_words_through(text):
    assert not findings(text)
