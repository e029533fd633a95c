"""What every report figure shares: the Agg backend, PNG bytes at one DPI, law colours and line styles,
legend labels, and which fits are one curve. Display units: rpm, deg, us/ms/s, N."""
from __future__ import annotations

import io
import threading

import numpy as np

from ...core.errors import FrictionLabError

LAW_COLORS = {"coulomb": "#7f7f7f", "area-rate": "#d95f02", "wear": "#1b9e77", "couette": "#7570b3"}
EXTRA_COLORS = ["#e7298a", "#66a61e", "#e6ab02", "#a6761d", "#1f78b4"]
DPI = 110
#: Two fits are one curve when they differ by at most this fraction of the noise at every data point.
SAME_CURVE = 1e-3


def _plt():
    from ...core.display import pyplot

    return pyplot()


#: zlib's level for the report's PNGs (Pillow's ``compress_level``): level 6 takes about twice the CPU for a
#: tenth fewer bytes on these flat-coloured figures.
PNG_LEVEL = 3


def _png(fig) -> bytes:
    """The figure as PNG bytes at DPI, drawn once by matplotlib's ``savefig`` (Pillow writes the file): the report's
    figures are placed by ``margins`` (a layout engine, or bbox_inches="tight", would draw the whole figure once
    more to measure it). No software stamp, so the bytes do not depend on the matplotlib version's name."""
    fig.set_dpi(DPI)
    raw = io.BytesIO()
    fig.savefig(raw, format="png", dpi=DPI, metadata={"Software": None}, pil_kwargs={"compress_level": PNG_LEVEL})
    _plt().close(fig)
    return raw.getvalue()


#: Per thread, the figure each kind of figure last drew on, by layout (``subplots``); at most KEEP of them.
_KEPT = threading.local()
KEEP = 12


def subplots(kind: str, nrows: int = 1, ncols: int = 1, figsize: tuple[float, float] = (6.4, 4.8), **kw):
    """(figure, 2-d array of its axes) as ``plt.subplots(nrows, ncols, figsize=figsize, squeeze=False, **kw)`` gives
    them, built outside pyplot and kept: the next figure of ``kind`` with the same layout is drawn on the same
    canvas, emptied (``_emptied``), which spares building the axes, their ticks and the renderer (and its
    measured text) once per dataset. Besides what ``_emptied`` resets, a kind of figure sets whatever it changes
    (tick locators, fonts, limits) on every figure it draws, so that each figure looks as on a fresh canvas."""
    return canvas((kind, nrows, ncols, tuple(figsize), repr(sorted(kw.items()))), figsize,
                  lambda fig: fig.subplots(nrows, ncols, squeeze=False, **kw))


def canvas(key, figsize: tuple[float, float], build):
    """(figure, what ``build(figure)`` returned: its axes) for the layout ``key`` (hashable, naming the kind of
    figure first), kept as ``subplots`` keeps its figures: the figure of a layout drawn before is handed back
    emptied (``_emptied``) and sized ``figsize`` again, with the axes its ``build`` made."""
    kept = _KEPT.__dict__.setdefault("figures", {})
    if key in kept:
        fig, axes = kept[key]
        _emptied(fig)
        fig.set_size_inches(figsize)
        return fig, axes
    fig = figure(figsize)
    axes = build(fig)
    if len(kept) >= KEEP:
        kept.pop(next(iter(kept)))
    kept[key] = fig, axes
    return fig, axes


def figure(figsize: tuple[float, float]):
    """A new matplotlib Figure of ``figsize`` inches, outside pyplot, on an Agg canvas (not kept)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    _plt()  # rcParams as every report figure has them (mathtext off)
    fig = Figure(figsize=figsize)
    FigureCanvasAgg(fig)
    return fig


def _emptied(fig) -> None:
    """``fig`` with what ``subplots`` gave first, as far as its kinds of figure change it: no artists, legends,
    titles, axis labels or figure texts; every axes visible, its axis on, its limits following the data and its
    colour cycle from the start."""
    for ax in fig.axes:
        for c in list(ax.containers):
            c.remove()
        for a in (*ax.lines, *ax.collections, *ax.patches, *ax.texts, *ax.images, *ax.artists, *ax.tables):
            a.remove()
        if ax.legend_ is not None:
            ax.legend_.remove()
        for loc in ("left", "center", "right"):
            ax.set_title("", loc=loc)
        ax.set_xlabel("")
        ax.set_ylabel("")
        ax.set_visible(True)
        ax.set_axis_on()
        ax.set_prop_cycle(None)
        ax.relim()
        ax.set_autoscale_on(True)
    for t in fig.texts:
        t.set_text("")
    for leg in list(fig.legends):
        leg.remove()


def release() -> None:
    """Let go of this thread's kept figures (``subplots``, ``canvas``) and trajectories (``trajectory``)."""
    _KEPT.__dict__.pop("figures", None)
    _KEPT.__dict__.pop("trajectories", None)


#: Inches: the blank border of the canvas; below an axes, its x tick labels and label (XTICKS: the labels
#: alone); between panels.
EDGE = 0.06
XAXIS = 0.46
XTICKS = 0.28
GAP = 0.15


def _lines_in(text: str, pt: float) -> float:
    """Inches the lines of ``text`` take at ``pt`` points."""
    return (text.count("\n") + 1) * 1.2 * pt / 72


def title_in(text: str, pt: float) -> float:
    """Inches an axes title ``text`` (its lines at ``pt`` points, and the pad under it) takes; 0 for none."""
    return _lines_in(text, pt) + 0.08 if text else 0.0


def suptitle(fig, text: str, pt: float) -> float:
    """The figure's title ``text`` at ``pt`` points, EDGE inches under the top; returns the inches it takes."""
    fig.suptitle(text, fontsize=pt, y=1 - EDGE / fig.get_figheight())
    return EDGE + _lines_in(text, pt) + 0.02


def margins(fig, top: float, bottom: float, right: float = EDGE, hspace: float = 0.0, left: float | None = None,
            wspace: float | None = None) -> None:
    """Place the figure's grid of axes at fixed margins in inches instead of running a layout engine (which
    draws the whole figure to measure it): ``top``, ``bottom``, ``right`` and the gap between rows ``hspace``
    as given, plus what the y axes take above their axes (an offset such as '1e8'); ``left`` and the gap
    between columns ``wspace`` (when None) the room the widest y axis takes (ticks, tick labels, label).
    Only the y axes are measured, never the whole figure."""
    fig.set_dpi(DPI)
    w, h = fig.get_size_inches()
    rows, cols = fig.axes[0].get_subplotspec().get_gridspec().get_geometry()
    fig.subplots_adjust(top=1 - top / h, bottom=bottom / h, hspace=_spacing(hspace, rows, h - top - bottom))
    axes = yaxes_in(fig)
    top += max((up for row, _, up in axes if row == 0), default=0.0)
    hspace += max((up for row, _, up in axes if row > 0), default=0.0)
    room = max((side for _, side, _ in axes), default=0.0)
    left = room + EDGE if left is None else left
    wspace = room + GAP if wspace is None else wspace
    fig.subplots_adjust(top=1 - top / h, bottom=bottom / h, hspace=_spacing(hspace, rows, h - top - bottom),
                        left=left / w, right=1 - right / w, wspace=_spacing(wspace, cols, w - left - right))


def legend_below(ax, drop: float = XAXIS, **kw) -> float:
    """A legend centred ``drop`` inches under ``ax`` (under its x axis: never over the data), in one column if
    its columns would not fit in the figure; returns the inches it reaches below the axes."""
    from matplotlib.transforms import ScaledTranslation

    fig = ax.figure
    fig.set_dpi(DPI)
    where = {"loc": "upper center", "bbox_to_anchor": (0.5, 0.0),
             "bbox_transform": ax.transAxes + ScaledTranslation(0.0, -drop, fig.dpi_scale_trans)}
    leg = ax.legend(**where, **kw)
    box = leg.get_window_extent(fig.canvas.get_renderer())
    if kw.get("ncol", 1) > 1 and box.width / fig.dpi > fig.get_figwidth() - 2 * EDGE:
        leg = ax.legend(**where, **{**kw, "ncol": 1})
        box = leg.get_window_extent(fig.canvas.get_renderer())
    return drop + box.height / fig.dpi


def _spacing(gap: float, n: int, span: float) -> float:
    """matplotlib's wspace/hspace (a fraction of the mean panel size) for a gap of ``gap`` inches between
    ``n`` panels sharing ``span`` inches."""
    return gap * n / (span - gap * (n - 1)) if n > 1 else 0.0


def yaxes_in(fig) -> list[tuple[int, float, float]]:
    """(grid row, inches left of its axes, inches above it) the y axis of each of ``fig``'s visible grid axes
    takes (ticks, tick labels and label; above, an offset text such as '1e8')."""
    renderer = fig.canvas.get_renderer()
    out = []
    for ax in fig.axes:
        if ax.get_visible() and ax.axison and ax.get_subplotspec() is not None:
            box, axes = ax.yaxis.get_tightbbox(renderer), ax.get_window_extent(renderer)
            if box is not None:
                out.append((ax.get_subplotspec().rowspan.start, max(0.0, axes.x0 - box.x0) / fig.dpi,
                            max(0.0, box.y1 - axes.y1) / fig.dpi))
    return out


def _style(law: str, solver: str, i: int) -> dict:
    color = LAW_COLORS.get(law, EXTRA_COLORS[i % len(EXTRA_COLORS)])
    ls = "--" if solver == "series" else "-"
    return {"color": color, "ls": ls, "lw": 1.8}


def _label(f, rows, laws=None, under=()) -> str:
    """'wear = couette [exact], ΔAIC 1.2' (the ranking row that holds the law, merged or not), and the
    candidates drawn under this curve (``under``: 'lies over coulomb [exact]')."""
    r = next((r for r in rows if f.law in (r.members or (r.law,)) and r.solver == f.solver), None)
    extra = f", ΔAIC {r.delta_aic:.1f}" if r is not None and r.rank is not None else ""
    name = " = ".join(laws or [f.law])
    if r is not None and len(r.members) > 1:  # the ranking's merged candidate: its name, its members not repeated
        name = r.law
        under = [u for u in under if u not in {f"{m} [{f.solver}]" for m in r.members}]
    hidden = f" (hides {', '.join(under)})" if under else ""
    return f"{name} [{f.solver}]{extra}{hidden}"


def wrapped(text: str, width_in: float, fontsize: float) -> str:
    """``text`` broken into lines that fit a figure ``width_in`` inches wide at ``fontsize`` points."""
    import textwrap

    return "\n".join(textwrap.wrap(text, max(20, int(width_in * 72 / (0.55 * fontsize)))))


#: A curve is hidden under another when they differ by less than this fraction of the plotted span everywhere.
HIDDEN = 4e-3


def visible_curves(curves, span: float) -> list[tuple[object, list[str], list[str]]]:
    """(fit, laws, hidden) for the curves of ``distinct_curves`` that can be seen: a curve within HIDDEN x
    ``span`` of an earlier one at every data point is not drawn, and is named in that one's legend entry."""
    out: list[tuple[object, list[str], list[str]]] = []
    for f, laws in curves:
        m = f.per_dataset[0].model
        for g, _, hidden in out:
            mg = g.per_dataset[0].model
            if mg.shape == m.shape and np.all(np.abs(mg - m) <= HIDDEN * span):
                hidden.append(f"{' = '.join(laws)} [{f.solver}]")
                break
        else:
            out.append((f, laws, []))
    return out


#: Trajectories ``trajectory`` keeps per thread at most (a long-lived worker drawing many reports lets go of them).
MEMO = 256


def trajectory(d, law: str, t):
    """``d.trajectory(law, t)`` (a DatasetFit's best-fit trajectory on the times ``t``, s), computed once per
    thread for the figures of one report (the fit, force and first-screen figures draw the same curves); a
    FrictionLabError (the solver's budget exceeded) is raised again on each call. Let go by ``release``."""
    memo = _KEPT.__dict__.setdefault("trajectories", {})
    if len(memo) >= MEMO:
        memo.clear()
    t = np.asarray(t, dtype=float)
    key = (id(d), law, t.shape, t.tobytes())
    hit = memo.get(key)
    if hit is None or hit[0] is not d:  # the fit itself kept beside its result: an id is never taken for another's
        try:
            hit = memo[key] = (d, d.trajectory(law, t), None)
        except FrictionLabError as e:
            hit = memo[key] = (d, None, e)
    if hit[2] is not None:
        raise hit[2]
    return hit[1]


def draw_fit(ax, f, obs: str, t, tf: float, uf: float, label: str, **style):
    """The fit ``f``'s ``obs`` as a dense curve over the span of the data times ``t`` (s), scaled by tf and uf;
    a stiff law whose dense curve exceeds the solver's budget draws its fitted points instead."""
    d = f.per_dataset[0]
    try:
        tr = trajectory(d, f.law, np.linspace(float(t[0]), float(t[-1]), 300))
        ax.plot(tr.t * tf, tr[obs] * uf, label=label, zorder=3, **style)
    except FrictionLabError:
        ax.plot(t * tf, d.model * uf, label=label, zorder=3, **style)


#: Points of a series beyond which a figure draws a thinned copy (``thinned``): at the report's figure widths
#: (about 800 pixels) a longer series puts several points on each pixel column.
THIN_AT = 4000
#: Columns of ``thinned``: more than the pixels across a panel.
THIN_BINS = 1000


def thinned(t, *series) -> np.ndarray:
    """Indices of the points of a long series that a figure needs to look as the whole does: all of them up to
    THIN_AT points; beyond, in each of THIN_BINS equal spans of ``t`` (sorted), the first and last point and
    those where each of ``series`` (arrays over ``t``) is lowest and highest (M4: Jugel et al., PVLDB 7,
    2014). With more columns than pixels, lines through these points cover the pixels that lines through every
    point do, to within a pixel; markers and error bars at each column's extremes reach where the whole cloud
    does."""
    n = len(t)
    if n <= THIN_AT:
        return np.arange(n)
    t = np.asarray(t, dtype=float)
    cut = np.searchsorted(t, np.linspace(t[0], t[-1], THIN_BINS + 1)[1:-1])
    starts = np.unique(np.concatenate([[0], cut]))
    keep = [starts, np.append(starts[1:] - 1, n - 1)]
    for y in series:
        y = np.asarray(y, dtype=float)
        for pick in (np.minimum, np.maximum):
            best = pick.reduceat(y, starts)
            # the first index of each span where y takes its extreme: spans are consecutive, so a running count
            hit = np.flatnonzero(y == np.repeat(best, np.diff(np.append(starts, n))))
            keep.append(hit[np.unique(np.searchsorted(starts, hit, side="right") - 1, return_index=True)[1]])
    return np.unique(np.concatenate(keep))


def same_curve(a, b) -> bool:
    """Whether two fits of one dataset with one solver predict the same curve at every data point (within
    SAME_CURVE sigma), or are the ranking's one candidate (laws spanning one closed-form family, fitted to one
    dataset: 'wear = couette'; their best fits differ only by the optimizer's tolerance): laws of one
    functional form, or a law whose extra term has no effect there."""
    from ...inference.verdicts.ranking import family_key

    if a.solver != b.solver or len(a.per_dataset) != len(b.per_dataset):
        return False
    if a.datasets == b.datasets and family_key(a) is not None and family_key(a) == family_key(b):
        return True
    for da, db in zip(a.per_dataset, b.per_dataset):
        if da.model.shape != db.model.shape or not np.all(np.abs(da.model - db.model) <= SAME_CURVE * da.target.sigma):
            return False
    return True


def distinct_curves(fits) -> list[tuple[object, list[str]]]:
    """(representative fit, the laws whose fits are that same curve, simplest first) for successful fits, in order."""
    out: list[tuple[object, list[str]]] = []
    for f in fits:
        if not f.ok:
            continue
        for rep, laws in out:
            if same_curve(rep, f):
                laws.append(f.law)
                break
        else:
            out.append((f, [f.law]))
    return [(f, simplest_first(laws)) for f, laws in out]


def simplest_first(laws) -> list[str]:
    """Laws of one curve in the order the ranking names them ('wear = couette'): fewest parameters first,
    then by name (inference.verdicts.ranking.merge_identical), so each merged candidate has one spelling."""
    from ...physics.registry import get_law

    def key(law):
        try:
            return (len(get_law(law).params), law)
        except Exception:  # a law no longer registered: by name after the others
            return (1 << 30, law)
    return sorted(set(laws), key=key)


def is_png(data: bytes) -> bool:
    return data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 100
