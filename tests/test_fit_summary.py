"""The fit summary a newcomer reads: its first line gives the goodness-of-fit verdict (not the optimizer's "ok"),
each note once, and two parameters the data cannot separate are said to be not separately identifiable."""
from __future__ import annotations

import frictionlab as fl


def test_the_head_gives_the_verdict_and_the_tests_agree():
    data = fl.load_dataset("impact-golf-v28")
    for solver, verdict in (("series", "fits"), ("exact", "does not fit")):
        r = fl.fit("wear", data, solver=solver)
        head, *rest = r.summary().splitlines()
        assert head.endswith(f": {verdict}"), head
        assert r.goodness.fits is (verdict == "fits")
        assert not head.endswith(": ok")


def test_a_pair_the_data_cannot_separate_is_named_as_such():
    r = fl.fit("wear", "impact-golf-v28", solver="exact", free={"u0": ("8 m/s", "14 m/s")})
    text = r.summary()
    assert "lam and u0 are correlated (r = -1.000)" in text
    assert "not separately identifiable" in text


def test_every_note_is_printed_once():
    import pytest

    try:
        data = fl.load_dataset("basalt-velstep4")  # a measured record: present beside the repository or not
    except fl.FrictionLabError as exc:
        pytest.skip(str(exc))
    f = fl.fit("rate-state-aging", data)
    assert f.notes and f.velstep is not None
    text = f.summary()
    for note in f.notes:
        assert text.count(note) == 1, note


def _listed(help_text: str, heading: str) -> dict[str, str]:
    """name -> help of each entry argparse lists under ``heading`` (COMMAND, ACTION), wrapped lines joined."""
    block = help_text.split(f"  {heading}\n", 1)[1].split("\n\n", 1)[0]
    entries: dict[str, str] = {}
    name = None
    for line in block.splitlines():
        words = line.split()
        if line.startswith("    ") and not line.startswith("      ") and words:
            name = words[0]
            entries[name] = " ".join(words[1:])
        elif name and words:
            entries[name] += " " + " ".join(words)
    return entries


def test_the_top_level_help_lists_every_command_and_every_datasets_action():
    import subprocess
    import sys
    from pathlib import Path

    cli = Path(sys.executable).with_name("frictionlab")
    top = subprocess.run([str(cli), "--help"], capture_output=True, text=True, check=True).stdout
    commands = _listed(top, "COMMAND")
    assert {"laws", "datasets", "simulate", "fit", "compare"} <= set(commands)
    actions = _listed(subprocess.run([str(cli), "datasets", "--help"], capture_output=True, text=True,
                                     check=True).stdout, "ACTION")
    assert {"show", "template", "rebuild", "import"} <= set(actions)
    for action in set(actions) - {"list"}:  # 'datasets' alone lists
        assert action in commands["datasets"], f"'datasets {action}' missing from --help: {commands['datasets']}"
