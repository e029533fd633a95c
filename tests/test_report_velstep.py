"""The first screen's measured velocity steps (report.velstep): each step's a, b, a - b, Dc and k with intervals
beside its figure (data, fit, residuals); nothing for synthetic or non-slider data."""
import shutil
import sys
from pathlib import Path

import attrs
import numpy as np
import pytest

from frictionlab import compare
from frictionlab.report import build, first_screen
from frictionlab.report import velstep as report_velstep
from frictionlab.report.figures import is_png
from frictionlab.report.render import html_page, markdown

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))


@pytest.fixture(scope="module")
def comp(tmp_path_factory):
    from calibration_ar1 import make_dataset

    ds, curve = make_dataset(tmp_path_factory.mktemp("step"), "none", quick=True)
    y = curve + np.random.default_rng(8).normal(0.0, 4e-4, curve.size)
    measured = attrs.evolve(ds, name="lab-step", columns=dict(ds.columns, mu=y), noise={"mu": 4e-4},
                            provenance=attrs.evolve(ds.provenance, kind="measured"))
    return compare(laws=["rate-state-aging", "rate-state-slip"], datasets=[measured, "spring-slider-small-step"],
                   equivalence=False, bootstrap=0)


def test_each_measured_step_has_its_table_row_and_figure(comp):
    steps = report_velstep.measured_steps(comp)
    assert [d.name for d, _ in steps] == ["lab-step"]  # the synthetic set is not a measured step
    sections, _ = build(comp, modules=[first_screen])
    md = markdown("t", sections)
    assert "**Measured velocity steps**" in md and "Dc [µm]" in md and "k [1/µm]" in md
    f = steps[0][1][0]
    row = next(line for line in md.splitlines() if line.startswith(f"| **lab-step** | {f.law[len('rate-state-'):]} |"))
    q = f.velstep.rows[0].quantities
    assert report_velstep.cell(q["a"]) in row and report_velstep.cell(q["Dc"]) in row and "±" in row
    fig = next(b[1] for s in sections for b in s.blocks if b[0] == "fig" and b[1].name == "velstep-lab-step.png")
    assert is_png(fig.draw())
    assert "trend" in fig.side  # what the fit says about the sign of a - b, beside the figure


def test_a_velocity_step_first_screen_speaks_of_its_own_data(comp):
    sections, _ = build(comp, modules=[first_screen])
    md = markdown("t", sections)
    assert "λAu" not in md and "paper" not in md and "series" not in md  # no word of the impact paper's questions
    # the measured step has its block; the synthetic one is left to the generic figure, which draws it alone
    from frictionlab.report.data_view import group_views

    views = group_views(comp, first_screen.series_findings(comp), skip={"lab-step"})
    assert [v.dataset.name for v in views] == ["spring-slider-small-step"]
    assert any(b[0] == "fig" and b[1].name == "finding.png" for s in sections for b in s.blocks)


def test_the_figure_table_gives_intervals_in_laboratory_units(comp):
    from frictionlab.report.figures.velstep import _table_text

    f = report_velstep.measured_steps(comp)[0][1][0]
    text = _table_text(f)
    q = f.velstep.rows[0].quantities
    assert "µm" in text and "1/µm" in text and f"[{q['Dc'].low:.{q['Dc'].digits}g}" in text


def test_a_velocity_step_figure_on_a_kept_canvas_is_the_figure_a_fresh_canvas_gives(comp):
    """The figures of the measured steps are drawn on one kept canvas (figures.base.canvas), emptied: each comes out
    as on a fresh canvas, byte for byte, whatever the figure before it showed."""
    from frictionlab.report.figures import base
    from frictionlab.report.figures.velstep import velstep_figure

    fits = [f for f in comp.fits if f.ok and getattr(f, "velstep", None) is not None]
    assert len(fits) >= 2
    base.release()
    kept = [velstep_figure(f) for f in fits + fits[:1]]
    fresh = []
    for f in fits + fits[:1]:
        base.release()
        fresh.append(velstep_figure(f))
    base.release()
    assert kept == fresh and kept[0] != kept[1]


@pytest.mark.skipif(shutil.which("chromium") is None, reason="chromium is not installed")
@pytest.mark.parametrize("width", [800, 1400])
def test_the_measured_steps_table_fits_the_page_at_800_and_1400_px(comp, tmp_path, width):
    """Headless Chromium lays out the first screen: the ten-column table of measured steps (a, b, a - b, Dc, k with
    their errors, the noise model, the law's fit) is no wider than its box, so no column is cut at the right."""
    import screenshot

    sections, _ = build(comp, modules=[first_screen])
    page = tmp_path / "report.html"
    page.write_text(html_page("t", sections, {f.name: b"" for s in sections for f in s.figures}), encoding="utf-8")
    tables = screenshot.table_widths(page, width=width)
    assert any(t["columns"] == 10 for t in tables), tables
    assert all(t["width"] <= t["box"] + 0.5 for t in tables), tables
