"""Platform conventions: the equivalence pairs chosen on the command line (--pairs LAW:LAW, repeated or with
commas, as every list option), and a one-line note where worker processes cannot be forked (runs serial)."""
from __future__ import annotations

import json

import pytest

from frictionlab.commands.compare import parse_pairs
from frictionlab.core import workers
from frictionlab.core.errors import FrictionLabError


def test_pairs_are_parsed_as_registered_names_among_the_compared_laws():
    assert parse_pairs(["wear:area-rate", "coulomb:wear"], None) == (("wear", "area-rate"), ("coulomb", "wear"))
    assert parse_pairs(["rate-state-aging:rate-state-slip"], ["rate-state-aging", "rate-state-slip"]) == (
        ("rate-state-aging", "rate-state-slip"),)
    for bad, match in (("wear", "expected LAW:LAW"), ("wear:wear", "two different laws"), ("a:b:c", "expected LAW:LAW"),
                       ("rate-state-aging:wear", "rate-state-aging is not among the compared laws"),
                       ("wear:no-such-law", "no-such-law")):
        with pytest.raises(FrictionLabError, match=match):
            parse_pairs([bad], None)


def test_compare_tests_the_pairs_given_on_the_command_line(run_cli, tmp_path):
    out = run_cli("compare", "--laws", "coulomb,wear,area-rate", "--data", "impact-golf-v28", "--pairs",
                  "coulomb:area-rate", "--pair", "area-rate:wear", "--bootstrap", "0", "--quiet", "--out",
                  tmp_path / "r")
    assert out.returncode == 0, out.stderr
    results = json.loads((tmp_path / "r" / "results.json").read_text())
    assert results["settings"]["pairs"] == [["coulomb", "area-rate"], ["area-rate", "wear"]]
    assert {(e["law_a"], e["law_b"]) for e in results["equivalence"]} == {("coulomb", "area-rate"), ("area-rate", "wear")}


def test_without_fork_the_run_is_serial_and_says_so(monkeypatch):
    def no_fork(method=None):
        raise ValueError(f"cannot find context for {method!r}")

    monkeypatch.setattr(workers, "get_context", no_fork)
    with pytest.warns(RuntimeWarning, match="cannot fork worker processes: the run is serial"):
        with workers.process_pool(2, "compare") as pool:
            assert pool is None
