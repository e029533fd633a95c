"""A per-dataset report figure is drawn on the canvas the last figure of its kind and layout used, emptied
(``report.figures.base.subplots``); each must come out as on a fresh canvas, byte for byte, whatever the figure
before it showed (other data, units, titles, legends, limits, a panel switched off). The same in a unit 1e5
times rpm: tests/test_report_fast_paths.py."""
import io

import attrs
import pytest
from _fit_helpers import TRUTH, synthetic

from frictionlab import compare, report
from frictionlab.io.dataset import load_dataset
from frictionlab.report.figures import base
from PIL import Image


def _figures(c):
    return [f for page in report._pages(c, {}) for sec in page[1] for f in sec.figures]


@pytest.fixture(scope="module")
def comparisons():
    series = [synthetic("area-rate", TRUTH["area-rate"], seed=3, name="a"),
              synthetic("coulomb", TRUTH["coulomb"], seed=4, rel_noise=0.05, name="b-" + "long-name-" * 6),
              synthetic("wear", TRUTH["wear"], seed=5, rel_noise=0.002, name="c")]
    outcome = load_dataset("impact-outcome-synthetic")
    return (compare(laws=["coulomb", "wear", "area-rate"], datasets=series),
            compare(laws=["coulomb", "wear"], datasets=[outcome, attrs.evolve(outcome, name="other")]))


@pytest.fixture(scope="module")
def figures(comparisons):
    return [f for c in comparisons for f in _figures(c)]


def test_each_figure_on_a_kept_canvas_is_the_figure_a_fresh_canvas_gives(figures, monkeypatch):
    emptied = []
    empty = base._emptied
    monkeypatch.setattr(base, "_emptied", lambda fig: (emptied.append(fig), empty(fig)))
    base.release()
    kept = [f.draw() for f in figures]
    fresh = []
    for f in figures:
        base.release()
        fresh.append(f.draw())
    base.release()
    kinds = {f.name.split("-")[0] for f in figures}
    assert {"fit", "force", "ranking.png", "discrimination", "equivalence", "derive", "finding.png"} <= kinds
    assert len(emptied) >= 8  # the canvases were drawn on again
    again = [fig._suptitle.get_text() for fig in emptied if fig._suptitle is not None]  # as the last figure left it
    assert any("spin derived from rotation angle" in t for t in again)
    assert [f.name for f, a, b in zip(figures, kept, fresh) if a != b] == []
    for data in kept:  # each a PNG Pillow reads at the figure's size
        image = Image.open(io.BytesIO(data))
        image.load()
        assert image.format == "PNG" and min(image.size) > 50


def test_the_first_screens_figure_on_a_kept_canvas_is_the_figure_a_fresh_canvas_gives(comparisons, monkeypatch):
    """A report of many groups draws one first-screen figure per group's page, mostly of one panel: each on the
    canvas the last one of its layout (panels, slip panels under them) used."""
    from frictionlab.report.data_view import group_views, title
    from frictionlab.report.figures import group_figure
    from frictionlab.report.first_screen import series_findings

    views = [v for c in comparisons for v in group_views(c, series_findings(c))]
    layouts = [v.series is not None for v in views]
    assert len(views) > len(set(layouts))  # two panels of one layout at least: a canvas drawn on again
    emptied = []
    empty = base._emptied
    monkeypatch.setattr(base, "_emptied", lambda fig: (emptied.append(fig), empty(fig)))
    base.release()
    kept = [group_figure([v], title([v])) for v in views]
    fresh = []
    for v in views:
        base.release()
        fresh.append(group_figure([v], title([v])))
    base.release()
    assert len(emptied) >= len(views) - len(set(layouts))
    assert [v.dataset.name for v, a, b in zip(views, kept, fresh) if a != b] == []
