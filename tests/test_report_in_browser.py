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


def _answer(group, best, goodness, eq="not tested", thr="", series="", transfer=""):
    """A row shaped like the built-in data's (seven groups, long sentences behind short cells)."""
    from frictionlab.inference.verdicts.answers import Answer

    long = "a sentence of sixty words that explains the verdict in full, with every p-value and number " * 3
    short = {k: v for k, v in (("best", best), ("goodness", goodness), ("equivalence", eq), ("threshold", thr),
                               ("series", series), ("transfer", transfer)) if v}
    return Answer(group=group, datasets=(f"{group}-a", f"{group}-b"), provenance="synthetic", best=best, fits=True,
                  headline=long, goodness=long, equivalence=eq, noise_threshold=long if thr else "",
                  series_vs_exact=long if series else "", transfer=long if transfer else "", short=short)


@pytest.fixture(scope="module")
def seven_groups(tmp_path_factory):
    """A report whose answers table has seven groups of long verdicts."""
    import attrs

    ds = synthetic("wear", {"lam": 1.81e6}, seed=2, n=26, name="impact-browser")
    c = compare(laws=["wear", "coulomb"], datasets=[ds], equivalence=False)
    rows = (_answer("impact-golf", "no law fits (best of a poor set: wear = couette [series])",
                    "fails: runs p = 8e-10", "different (exact and series)",
                    "differ unless σ > 1.8 / 1.9 deg (σ = 0.5 deg)", "series slip u = 0 at 338 / 369 µs; exact never",
                    "one wear [series] fit for both: no (p = 2e-78)"),
            _answer("impact-outcome", "coulomb [exact] ✓", "fits: runs p = 0.84"),
            _answer("incline-dry", "wear = couette [ode] ✓", "fits: χ² p = 0.2",
                    transfer="one wear [ode] fit for both: yes (p = 0.051)"),
            _answer("incline-oil", "wear = couette [exact] ✓", "fits: runs p = 0.66", "different (exact)",
                    "differ unless σ > 0.4 / 0.27 / 0.15 m/s (σ = 0.003 m/s)",
                    transfer="one wear [exact] fit for all: yes (p = 0.44)"),
            _answer("kharaz2001", "coulomb [exact] ✓", "fits: runs p = 0.11",
                    transfer="no transfer: different observables"),
            _answer("spring-slider", "no law fits (best of a poor set: wear = couette [exact+ode])",
                    "fails: χ² p < 1e-300"),
            _answer("spring-slider-small", "no law could be fitted", ""))
    return write_report(attrs.evolve(c, answers=rows), tmp_path_factory.mktemp("seven") / "rep")


def test_seven_groups_of_long_verdicts_still_leave_the_finding_on_the_first_screen(seven_groups):
    box = screenshot.first_screen_layout(seven_groups / "report.html", height=1000)
    assert box["table"] is not None and box["figure"] is not None
    assert box["table"]["bottom"] <= box["figure"]["top"] < box["figure"]["bottom"] <= 1000, box


@pytest.mark.parametrize("width", [800, 1400])
def test_every_table_fits_its_box_at_800_and_1400_px(seven_groups, width):
    """No column is cut at the right edge of a window 800 or 1400 px wide: every table, the answers table of long
    verdicts in every column too, is no wider than the box it lies in."""
    tables = screenshot.table_widths(seven_groups / "report.html", width=width)
    assert tables[0]["columns"] >= 7, tables  # the answers table
    assert all(t["width"] <= t["box"] + 0.5 for t in tables), tables
