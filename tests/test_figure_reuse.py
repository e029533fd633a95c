"""A per-dataset report figure is drawn on the canvas the last figure of its kind and layout used, emptied
(``report.figures.base.subplots``); each must come out as on a fresh canvas, byte for byte, whatever the figure
before it showed (other data, units, titles, legends, limits, a panel switched off)."""
import attrs
import pytest
from _fit_helpers import TRUTH, synthetic

from frictionlab import compare, report
from frictionlab.io.dataset import load_dataset
from frictionlab.report.figures import base


def _figures(c):
    return [f for page in report._pages(c, {}) for sec in page[1] for f in sec.figures]


@pytest.fixture(scope="module")
def figures():
    series = [synthetic("area-rate", TRUTH["area-rate"], seed=3, name="a"),
              synthetic("coulomb", TRUTH["coulomb"], seed=4, rel_noise=0.05, name="b-" + "long-name-" * 6),
              synthetic("wear", TRUTH["wear"], seed=5, rel_noise=0.002, name="c")]
    outcome = load_dataset("impact-outcome-synthetic")
    return (_figures(compare(laws=["coulomb", "wear", "area-rate"], datasets=series))
            + _figures(compare(laws=["coulomb", "wear"], datasets=[outcome, attrs.evolve(outcome, name="other")])))


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
    assert {"fit", "force", "discrimination", "equivalence"} <= kinds
    assert len(emptied) >= 6  # the canvases were drawn on again
    assert [f.name for f, a, b in zip(figures, kept, fresh) if a != b] == []
