"""What the report's figures compute once and share, against computing it each time: a best-fit trajectory drawn
by several figures (figures.base.trajectory) and the Hertz pulse at one time (an ODE's right-hand side) against
the same pulse at an array of times."""
import os

import numpy as np
import pytest
from _fit_helpers import TRUTH, synthetic

from frictionlab import fit
from frictionlab.core.errors import FrictionLabError
from frictionlab.report.figures import base
from frictionlab.solve.outcomescene import HertzPulse, hertz_shape


@pytest.fixture(scope="module")
def wear_fit():
    return fit("wear", synthetic("wear", TRUTH["wear"], seed=5, rel_noise=0.01, name="c"))


def test_a_trajectory_is_simulated_once_per_report_and_is_the_fits_own(wear_fit, monkeypatch):
    d = wear_fit.per_dataset[0]
    t = np.linspace(0.0, float(d.target.t[-1]), 300)
    calls = []
    own = type(d).trajectory
    monkeypatch.setattr(type(d), "trajectory", lambda self, law, tt: (calls.append(len(tt)), own(self, law, tt))[1])
    base.release()
    first = base.trajectory(d, "wear", t)
    again = base.trajectory(d, "wear", t.copy())  # the same times: the same curve, not simulated again
    other = base.trajectory(d, "wear", t[:200])
    assert calls == [300, 200] and again is first and len(other.t) == 200
    plain = own(d, "wear", t)
    assert np.array_equal(first.t, plain.t) and np.array_equal(first.force, plain.force)
    assert np.array_equal(first["omega"], plain["omega"])
    base.release()  # a report's end: computed anew
    assert base.trajectory(d, "wear", t) is not first and calls == [300, 200, 300]
    base.release()


def test_a_trajectory_the_solver_refuses_is_refused_each_time(wear_fit, monkeypatch):
    d = wear_fit.per_dataset[0]

    def refuse(self, law, t):
        raise FrictionLabError("over the budget")

    monkeypatch.setattr(type(d), "trajectory", refuse)
    base.release()
    for _ in range(2):
        with pytest.raises(FrictionLabError, match="over the budget"):
            base.trajectory(d, "wear", np.linspace(0.0, 1e-3, 5))
    base.release()


def test_the_memo_lets_go_beyond_its_size(wear_fit):
    d = wear_fit.per_dataset[0]
    base.release()
    for k in range(base.MEMO + 3):
        base.trajectory(d, "wear", np.linspace(0.0, 1e-4, 3 + k))
    assert len(base._KEPT.trajectories) <= base.MEMO
    base.release()


def test_the_hertz_pulse_at_one_time_is_the_pulse_at_an_array_of_times():
    pulse = HertzPulse(stiffness=2.3e9, delta_max=4e-5, normal_speed=1.7)
    s_end = hertz_shape()[0]
    ts = pulse.time_scale * np.concatenate([np.random.default_rng(0).uniform(-0.1, 1.1 * s_end, 4000),
                                            [0.0, s_end, -0.0, np.nextafter(s_end, 9.0), 1e-300, np.nan, np.inf]])
    many = pulse.shape(ts)
    for k, t in enumerate(ts):
        one = pulse.shape(t)
        assert all(isinstance(v, (np.ndarray, np.floating)) and np.shape(v) == () for v in one)
        assert (one[0], one[1]) == (many[0][k], many[1][k]) or (np.isnan(t) and one == (0.0, 0.0)), t
    inside = (ts >= 0) & (ts <= s_end * pulse.time_scale)
    assert inside.sum() > 3000 and np.all(many[0][~inside] == 0.0)


@pytest.mark.parametrize("n, nan", [(5000, False), (7, False), (40, True)])
def test_error_bars_from_plain_arrays_are_matplotlibs_error_bars(n, nan):
    """base.errorbar against Axes.errorbar: the same PNG bytes (bars, markers, legend entry, axis limits) and
    the same artists; a NaN takes matplotlib's own way."""
    rng = np.random.default_rng(n)
    x = np.sort(rng.uniform(0.0, 3.0, n))
    y, err = np.sin(x) + rng.normal(0.0, 0.1, n), rng.uniform(0.01, 0.2, n)
    if nan:
        y[3] = np.nan
    pngs, kinds = [], []
    for way in ("matplotlib", "plain"):
        base.release()
        fig, ((ax,),) = base.subplots("errorbar-test", figsize=(7.6, 3.8))
        style = {"fmt": "o", "ms": 3.2, "color": "black", "ecolor": "0.7", "elinewidth": 0.8, "label": "data",
                 "zorder": 1}
        c = ax.errorbar(x, y, yerr=err, **style) if way == "matplotlib" else base.errorbar(ax, x, y, err, **style)
        ax.legend()
        kinds.append([type(a).__name__ for a in ax.get_children()][:4] + [len(c.lines[2][0].get_segments())])
        assert "vlines" not in vars(ax)  # the axes is left as it was
        base.margins(fig, top=0.1, bottom=0.5)
        pngs.append(base._png(fig))
    base.release()
    assert kinds[0] == kinds[1] and kinds[0][-1] == n
    assert pngs[0] == pngs[1]


def _texts(canvas):
    """A figure of ``canvas`` (a FigureCanvasAgg class) with texts at many sub-pixel places: repeated strings,
    sizes, angles, several lines, glyphs from a fallback font, and text drawn without antialiasing."""
    from matplotlib.figure import Figure

    base._plt()
    fig = Figure(figsize=(5.0, 4.0), dpi=base.DPI)
    canvas(fig)
    rng = np.random.default_rng(7)
    words = ["0.5", "1e+08", "ΔAIC 1.2 (hides #3 wear [exact])", "Ψ2 against Ψ1, μ = 0.092\nsecond line", "g y p ∡"]
    for k in range(80):
        fig.text(rng.uniform(0.0, 0.8), rng.uniform(0.0, 0.9), words[k % 5], fontsize=(6.5, 7, 8, 12)[k % 4],
                 rotation=(0, 35, 90)[k % 3], antialiased=k % 7 != 0)
    return fig


def _glyphs_on_the_grid(monkeypatch):
    """matplotlib's RendererAgg drawing each glyph of plain text at its origin (26.6 fixed point) rounded to a
    multiple of agg.STEP, halves up: its own glyph drawer given each glyph's offset moved there."""
    import math
    import types

    from matplotlib.backends.backend_agg import RendererAgg

    from frictionlab.report.figures import agg

    own_text, own_glyphs = RendererAgg.draw_text, RendererAgg._draw_text_glyphs_and_boxes

    def on_grid(v):
        return (round(0x40 * v) + agg.STEP // 2) // agg.STEP * agg.STEP / 0x40

    def moved(self, gc, x, y, angle, glyphs, boxes):
        cos, sin = math.cos(math.radians(angle)), math.sin(math.radians(angle))
        up = self.height - y
        out = []
        for font, size, index, slant, extend, dx, dy in glyphs:
            gx = on_grid(x + dx * cos - dy * sin) - x
            gy = on_grid(up + dx * sin + dy * cos) - up
            out.append((font, size, index, slant, extend, gx * cos + gy * sin, gy * cos - gx * sin))
        return own_glyphs(self, gc, x, y, angle, out, boxes)

    def draw_text(self, gc, x, y, s, prop, angle, ismath=False, mtext=None):
        if not ismath:
            self._draw_text_glyphs_and_boxes = types.MethodType(moved, self)
        try:
            return own_text(self, gc, x, y, s, prop, angle, ismath, mtext)
        finally:
            vars(self).pop("_draw_text_glyphs_and_boxes", None)

    monkeypatch.setattr(RendererAgg, "draw_text", draw_text)


def test_text_drawn_with_the_kept_measures_is_matplotlibs_text_on_a_quarter_pixel_grid(monkeypatch):
    """agg.Renderer (each string measured and laid out once, each glyph rendered once per phase of its origin on
    the grid) against matplotlib's RendererAgg: the same boxes and line metrics; the PNG bytes of matplotlib drawing
    each glyph at its origin rounded to the grid, on a first draw and on one that takes everything from what was
    kept; on the finest grid (1/64 pixel), matplotlib's own PNG bytes."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from frictionlab.report.figures import agg

    base.release()
    plain = _texts(FigureCanvasAgg)
    kept = _texts(agg.Canvas)
    r0, r1 = plain.canvas.get_renderer(), kept.canvas.get_renderer()
    assert type(r1) is agg.Renderer and type(r0) is not agg.Renderer
    for a, b in zip(plain.texts, kept.texts):
        for s in a.get_text().split("\n"):
            prop = a.get_fontproperties()
            assert r0.get_text_width_height_descent(s, prop, False) == r1.get_text_width_height_descent(s, prop, False)
        assert a.get_window_extent(r0).bounds == b.get_window_extent(r1).bounds
    png = base._png(plain)
    first = base._png(kept)
    glyphs = len(agg._KEPT.glyphs)
    if agg._LAYOUT:  # matplotlib 3.11 on: glyphs drawn one at a time (before, RendererAgg draws them)
        assert 0 < glyphs < sum(len(t.get_text()) for t in kept.texts)  # a glyph at one phase is rendered once
        assert first != png  # glyphs moved (by at most 1/8 pixel)
    again = _texts(agg.Canvas)
    assert base._png(again) == first
    assert len(agg._KEPT.glyphs) == glyphs  # the second figure took every glyph from the first
    with monkeypatch.context() as m:
        _glyphs_on_the_grid(m)
        assert base._png(_texts(FigureCanvasAgg)) == first
    with monkeypatch.context() as m:
        m.setattr(agg, "STEP", 1)
        base.release()
        assert base._png(_texts(agg.Canvas)) == png
        assert len(agg._KEPT.glyphs) > glyphs or not agg._LAYOUT  # more phases, more bitmaps
    base.release()
    assert not vars(agg._KEPT)


def _two_panels(fig):
    """A fit figure's layout: data over residuals sharing x, a title, y labels and an offset text (1e8)."""
    (ax,), (axr,) = fig.subplots(2, 1, squeeze=False, sharex=True)
    t = np.linspace(0.0, 2.0, 50)
    ax.plot(t, 3e8 + 1e6 * np.sin(t), label="data")
    axr.plot(t, 1e-3 * np.cos(t))
    ax.set_title("a title over the data, long enough to reach the offset text above the y axis")
    ax.set_ylabel("spin [rpm]")
    axr.set_ylabel("model − data")
    axr.set_xlabel("time [ms]")
    ax.legend()
    base.margins(fig, top=0.5, bottom=0.5, hspace=base.GAP)


def test_an_axis_works_out_its_ticks_once_in_a_draw(monkeypatch):
    """Inside ticks.same, each axis works out its ticks once in a draw (matplotlib: three to six times), and the
    figure is the one matplotlib draws without it."""
    import contextlib

    from matplotlib.axis import Axis

    from frictionlab.report.figures import ticks

    computed = []
    own = Axis._update_ticks
    monkeypatch.setattr(Axis, "_update_ticks", lambda self: (computed.append(self), own(self))[1])
    pngs, counts, offsets = [], [], []
    for window in (ticks.same, lambda fig: contextlib.nullcontext()):
        monkeypatch.setattr(ticks, "same", window)
        base.release()
        fig = base.figure((6.0, 5.0))
        _two_panels(fig)
        del computed[:]
        pngs.append(base._png(fig))
        counts.append(len(computed))
        offsets.append(fig.axes[0].yaxis.offsetText.get_text())
    base.release()
    assert counts[0] == 4 and counts[1] > 8  # 2 axes of 2 panels
    assert pngs[0] == pngs[1]
    assert offsets[0] == offsets[1] != ""  # the title is placed over the y axis' offset text


@pytest.fixture(scope="module")
def small_comparisons():
    from frictionlab import compare
    from frictionlab.io.dataset import load_dataset

    series = [synthetic("area-rate", TRUTH["area-rate"], seed=3, name="a"),
              synthetic("wear", TRUTH["wear"], seed=5, rel_noise=0.002, name="c-" + "long-name-" * 4)]
    return (compare(laws=["coulomb", "wear", "area-rate"], datasets=series),
            compare(laws=["coulomb", "wear"], datasets=[load_dataset("impact-outcome-synthetic")]))


@pytest.mark.parametrize("scale", [1.0, 1e5])
def test_the_reports_figures_are_the_ones_matplotlib_draws_without_the_fast_paths(small_comparisons, scale,
                                                                                   monkeypatch):
    """Every figure of two reports (fits, force, ranking, discrimination, equivalence, first screen, outcomes;
    spin also in a unit 1e5 times rpm: offset texts above the axes) drawn with agg.Canvas and ticks.same, and
    with matplotlib's FigureCanvasAgg and no tick window drawing each glyph at its origin on agg.STEP's grid: the
    same PNG bytes; where these paths do not follow, matplotlib's own PNG bytes."""
    import contextlib

    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from frictionlab import report
    from frictionlab.core import display
    from frictionlab.report.figures import agg, ticks

    name, factor = display.OBSERVABLE_UNITS["omega"]
    monkeypatch.setitem(display.OBSERVABLE_UNITS, "omega", (name, factor * scale))
    figures = [f for c in small_comparisons for page in report._pages(c, {}) for sec in page[1] for f in sec.figures]
    assert {"fit", "force", "ranking", "discrimination", "finding"} <= {f.name.split("-")[0].split(".")[0]
                                                                       for f in figures}
    base.release()
    fast = [f.draw() for f in figures]
    monkeypatch.setattr(agg, "Canvas", FigureCanvasAgg)
    monkeypatch.setattr(ticks, "same", lambda fig: contextlib.nullcontext())
    base.release()
    plain = [f.draw() for f in figures]
    with monkeypatch.context() as m:
        _glyphs_on_the_grid(m)
        on_grid = [f.draw() for f in figures]
    base.release()
    assert [f.name for f, a, b in zip(figures, fast, on_grid) if a != b] == []
    assert fast != plain or not agg._LAYOUT  # glyphs moved (by at most 1/8 pixel)
    # with a matplotlib these paths do not follow: agg.Canvas draws text as RendererAgg does, no tick window
    monkeypatch.undo()
    monkeypatch.setitem(display.OBSERVABLE_UNITS, "omega", (name, factor * scale))
    monkeypatch.setattr(agg, "_LAYOUT", False)
    monkeypatch.setattr(ticks, "SUPPORTED", False)
    gated = [f.draw() for f in figures]
    base.release()
    assert [f.name for f, a, b in zip(figures, plain, gated) if a != b] == []


def _kept_in_a_forked_child(queue):
    from frictionlab.report.figures import agg

    queue.put(sorted(k for k, v in agg._KEPT.__dict__.items() if v))


@pytest.mark.skipif(not hasattr(os, "fork"), reason="no fork on this platform")
def test_a_forked_worker_starts_without_the_parents_kept_glyphs():
    """The kept layouts and glyphs hold fonts that read their files through descriptors a fork shares: a worker
    process forked from a report drawer lets go of them, as matplotlib's font cache does."""
    import multiprocessing

    from frictionlab.report.figures import agg

    base.release()
    fig = base.figure((2.0, 1.0))
    fig.text(0.1, 0.5, "kept glyphs")
    base._png(fig)
    assert agg._KEPT.__dict__.get("glyphs")
    ctx = multiprocessing.get_context("fork")
    queue = ctx.Queue()
    child = ctx.Process(target=_kept_in_a_forked_child, args=(queue,))
    child.start()
    seen = queue.get(timeout=60)
    child.join(60)
    assert seen == [] and agg._KEPT.__dict__.get("glyphs")
    base.release()
