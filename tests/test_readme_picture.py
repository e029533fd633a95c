"""The README's picture is the current code's: the answers table saved beside it (docs/images/first-screen.json,
written with the picture by ``python tools/screenshot.py --readme``) equals that of a fresh run of the README's main
job, but for the CPU-time ratios."""
from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
spec = importlib.util.spec_from_file_location("screenshot", ROOT / "tools" / "screenshot.py")
screenshot = importlib.util.module_from_spec(spec)
spec.loader.exec_module(screenshot)


def test_the_rows_are_read_from_a_report(tmp_path):
    md = tmp_path / "report.md"
    md.write_text("# t\n\n## Answers\n\n> note\n\n| dataset group | best law | what accuracy costs |\n|---|---|---|\n"
                  "| **a** | wear ✓ | 0.5× |\n| **b** | coulomb | 2× |\n\nmore\n", encoding="utf-8")
    assert screenshot.first_screen_rows(md) == {"columns": ["dataset group", "best law"],
                                                "rows": [["**a**", "wear ✓"], ["**b**", "coulomb"]]}


def test_the_readme_picture_shows_what_the_current_code_gives(tmp_path):
    import frictionlab as fl

    saved = json.loads(screenshot.README_ROWS.read_text(encoding="utf-8"))
    measured = [n for n in ("sepiolite-velstep1", "basalt-velstep4") if f"**{n}**" in {r[0] for r in saved["rows"]}]
    for name in measured:  # the picture was made with the measured records present
        try:
            fl.load_dataset(name)
        except fl.FrictionLabError as exc:
            pytest.skip(f"the README's picture includes measured records that are not here: {exc}")
    fresh = screenshot.first_screen_rows(screenshot.run_readme_job(tmp_path) / "report.md")
    assert fresh == saved, ("the README's picture is stale: run `python tools/screenshot.py --readme` and commit "
                            "docs/images/first-screen.png and .json")
