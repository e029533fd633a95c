"""The report's figures are placed at fixed margins (figures.base.margins), without a layout engine: every figure
is drawn once, and what it shows lies inside its canvas, panels and titles apart, with no wide blank border,
on the built-in kinds of data and on awkward ones (a long dataset name, tick labels of 1e+08 or 0.0004)."""
import attrs
import matplotlib.figure
import numpy as np
import pytest
from _fit_helpers import TRUTH, synthetic

from frictionlab import compare, write_report
from frictionlab.core import display
from frictionlab.io.dataset import load_dataset
from frictionlab.solve import rebound

LONG = "a-long-user-dataset-name-from-the-lab-notebook-2026-11-24-run-07-sphere-on-steel"

#: Inches: the most blank border a figure may leave on a side.
BLANK = 0.3


@pytest.fixture(scope="module")
def comparisons():
    ds = synthetic("area-rate", TRUTH["area-rate"], seed=11, name=LONG)
    outcome = load_dataset("impact-outcome-synthetic")
    return {"impact, long name": compare(laws=["wear", "area-rate"], datasets=[ds]),
            "impact outcomes, long name": compare(laws=["coulomb", "wear"],
                                                  datasets=[attrs.evolve(outcome, name=LONG)]),
            "stated numbers": compare(laws=["wear", "coulomb"], datasets=[load_dataset("impact-golf-v28")]),
            "two datasets, long name": compare(laws=["wear", "area-rate"], datasets=[
                ds, synthetic("wear", TRUTH["wear"], seed=12, name=LONG + "-second")], bootstrap=0)}


def problems(fig) -> list[str]:
    """What is wrong with a figure's placement: anything (axes with their ticks, labels, titles and legends; the
    figure's title) outside the canvas, two of them overlapping, or a blank border wider than BLANK."""
    r = fig.canvas.get_renderer()
    boxes = [(f"axes {i} {ax.get_title()!r}", ax.get_tightbbox(r)) for i, ax in enumerate(fig.axes)
             if ax.get_visible() and ax.axison]
    boxes += [(f"text {t.get_text()!r}", t.get_window_extent(r)) for t in fig.texts if t.get_text()]
    out, canvas, tol = [], fig.bbox, 1.0  # pixels
    for name, b in boxes:
        if b.x0 < canvas.x0 - tol or b.y0 < canvas.y0 - tol or b.x1 > canvas.x1 + tol or b.y1 > canvas.y1 + tol:
            out.append(f"{name} outside the canvas: {b.bounds} not in {canvas.bounds}")
    for i, (na, a) in enumerate(boxes):
        for nb, b in boxes[i + 1:]:
            if min(a.x1, b.x1) - max(a.x0, b.x0) > tol and min(a.y1, b.y1) - max(a.y0, b.y0) > tol:
                out.append(f"{na} overlaps {nb}")
    if any(n.startswith("axes") for n, _ in boxes):
        x0, y0 = min(b.x0 for _, b in boxes), min(b.y0 for _, b in boxes)
        x1, y1 = max(b.x1 for _, b in boxes), max(b.y1 for _, b in boxes)
        for side, gap in (("left", x0 - canvas.x0), ("bottom", y0 - canvas.y0), ("right", canvas.x1 - x1),
                          ("top", canvas.y1 - y1)):
            if gap > BLANK * fig.dpi:
                out.append(f"{gap / fig.dpi:.2f} in blank on the {side}")
    return out


@pytest.fixture
def checked(monkeypatch):
    """Every figure saved from here on: (its title, what is wrong with its placement, how often it was drawn)."""
    seen, draws = [], []
    save, draw = matplotlib.figure.Figure.savefig, matplotlib.figure.Figure.draw

    def counted(fig, renderer):
        draws.append(fig)
        return draw(fig, renderer)

    def saving(fig, *args, **kwargs):
        name = next((t.get_text() for t in fig.texts if t.get_text()), "") or fig.axes[0].get_title()
        found = problems(fig)
        before = len(draws)
        save(fig, *args, **kwargs)
        seen.append((name, found, sum(d is fig for d in draws[before:])))

    monkeypatch.setattr(matplotlib.figure.Figure, "draw", counted)
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", saving)
    return seen


@pytest.mark.parametrize("case", ["impact, long name", "impact outcomes, long name", "stated numbers",
                                  "two datasets, long name"])
def test_every_figure_is_drawn_once_and_shows_everything_apart_inside_its_canvas(case, comparisons, checked, tmp_path):
    write_report(comparisons[case], tmp_path / "rep")
    assert len(checked) >= 2
    if case.startswith("two datasets"):  # the ranking heat map (drawn across two datasets or more)
        assert any(name.startswith("Ranking per dataset") for name, _, _ in checked)
    assert [(name, draws) for name, _, draws in checked if draws != 1] == []
    assert [(name, found) for name, found, _ in checked if found] == []


@pytest.mark.parametrize("scale", [1e5, 1e-4])
def test_tick_labels_of_any_size_keep_their_room(scale, comparisons, checked, tmp_path, monkeypatch):
    """Spin shown in a unit 1e5 or 1e-4 times rpm: tick labels like 1e+08 (an offset above the axis) or 0.0004."""
    name, factor = display.OBSERVABLE_UNITS["omega"]
    monkeypatch.setitem(display.OBSERVABLE_UNITS, "omega", (name, factor * scale))
    write_report(comparisons["impact, long name"], tmp_path / "rep")
    assert [(n, f) for n, f, _ in checked if f] == []


def test_the_psi_figure_of_the_solve_layer_is_placed_the_same_way(checked):
    p1 = np.linspace(0.1, 11.0, 22)
    curves = {"psi1": p1, "closed_form": np.minimum(p1 - 5.0, 0.0), "rigid": np.minimum(p1 - 5.0, 0.0),
              "mindlin-deresiewicz": -np.sin(p1) * 1.5}
    png = rebound.psi_figure(curves, (p1[::3], -np.sin(p1[::3]) * 1.5), f"{LONG}: Ψ2 against Ψ1, μ = 0.092, 3.9 m/s")
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    ((name, found, draws),) = checked
    assert draws == 1 and not found, (name, found)
