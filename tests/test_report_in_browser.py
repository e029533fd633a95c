"""The report as a reader sees it: headless Chromium renders report.html; the first screen (1400 x 1000 px)
holds the verdict table and the finding figure. Skipped when Chromium is not installed."""
import sys
from pathlib import Path

import pytest

from _fit_helpers import synthetic
from frictionlab import compare, write_report

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))
import screenshot  # noqa: E402

pytestmark = pytest.mark.skipif(screenshot.chromium() is None, reason="chromium is not installed")


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    ds = synthetic("wear", {"lam": 1.81e6}, seed=2, n=26, name="impact-browser")
    c = compare(laws=["wear", "coulomb"], datasets=[ds], equivalence=False)
    return write_report(c, tmp_path_factory.mktemp("browser") / "rep")


def test_first_screen_shows_the_verdict_table_and_the_finding(report):
    box = screenshot.first_screen_layout(report / "report.html", height=1000)
    assert box["table"] is not None and box["figure"] is not None
    assert 0 < box["table"]["top"] < box["table"]["bottom"] <= 1000
    assert box["table"]["bottom"] <= box["figure"]["top"] < box["figure"]["bottom"] <= 1000
    assert box["figure"]["width"] > 450  # readable, not a thumbnail


def test_screenshot_is_written(report, tmp_path):
    png = screenshot.screenshot(report / "report.html", tmp_path / "shot.png", height=1000)
    data = png.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert int.from_bytes(data[16:20], "big") == 1400 and int.from_bytes(data[20:24], "big") == 1000
