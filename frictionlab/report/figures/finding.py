"""The first screen's figure: each dataset group's data with its top-ranked candidates, and the slip of the
truncated series against the exact solution where that series is among them."""
from __future__ import annotations

import numpy as np

from ...core.display import NAMES, time_unit, unit
from . import base


#: panels side by side in one row of the first screen's figure (five fill the page's width)
PER_ROW = 5


def group_figure(views, title: str) -> bytes:
    """The first screen's figure: per view (report.data_view.DataView: one dataset of a group with the group's
    top-ranked candidates) one panel, PER_ROW to a row, and under a panel whose candidates include the
    truncated series, the slip u(t) of that series and of the exact fit of the same law. A dataset without time
    (one impact per row) shows its observable against impact angle. Drawn once, then placed as it measures:
    each column as wide as its tick labels need, each row as tall as its titles, legends and axes need."""
    from .fits import against_angle, angle_column

    n = len(views)
    cols = min(n, PER_ROW)
    grid = [views[k:k + cols] for k in range(0, n, cols)]
    axw = {1: 4.7, 2: 3.7}.get(cols, 2.4)  # inches: few panels are drawn larger, five fill the page's width
    axh, slip_h, under = 1.55 + 0.25 * (axw - 2.4), 0.85, 0.15  # slip panel, and its gap under the data panel
    cell_w, cell_h = axw + 2.0, axh + under + slip_h + 2.0  # provisional: each axes at its final size, apart
    slip = tuple(v.series is not None for v in views)  # the panels with a slip panel under them
    fig, axes = base.canvas(("finding", cols, slip), (cols * cell_w, len(grid) * cell_h),
                            lambda fig: [(fig.add_axes((0, 0, 1, 1)), fig.add_axes((0, 0, 1, 1)) if s else None)
                                         for s in slip])
    fig.set_dpi(base.DPI)
    title = base.wrapped(title, cols * (axw + 0.8), 10)
    fig.suptitle(title, fontsize=10)
    panels = []  # (row, column, data axes, slip axes or None)
    for k, (v, (ax, ax_s)) in enumerate(zip(views, axes)):
        r, j = divmod(k, cols)
        ax.set_position(_box(fig, 1.0 + j * cell_w, 1.0 + r * cell_h, axw, axh))
        if ax_s is not None:
            ax_s.set_position(_box(fig, 1.0 + j * cell_w, 1.0 + r * cell_h + axh + under, axw, slip_h))
        panels.append((r, j, ax, ax_s))
        _group_panel(ax, ax_s, v, axw, against_angle, angle_column)
    _place(fig, panels, axw, axh, slip_h, under, title)
    return base._png(fig)


def _group_panel(ax, ax_s, v, axw, against_angle, angle_column) -> None:
    """One group's panel: the data and its top-ranked candidates; the slip panel under it where given."""
    d = v.dataset
    curves = [(f, label, base._style(f.law, f.solver, i)) for i, (f, label) in enumerate(zip(v.fits, v.labels))]
    target = v.fits[0].per_dataset[0].target
    curves = _merged(curves, float(np.ptp(target.y)) if np.size(target.y) > 1 else 0.0)
    if target.t is not None:
        xlabel = _against_time(ax, d, target, curves)
    elif angle_column(d) is not None:
        against_angle(ax, d, curves)
        xlabel = ax.get_xlabel()
    else:
        ax.set_axis_off()
        return
    name = v.group + ("" if v.group == d.name else f": {d.name}")
    ax.set_title(base.wrapped(name + ("" if d.provenance.kind == "measured" else f" ({d.provenance.kind})"),
                              axw + 0.3, 9), fontsize=9, pad=3)
    ax.grid(alpha=0.3)
    ax.tick_params(labelsize=7)
    ax.yaxis.label.set_size(8)
    ax.legend(fontsize=6.5, loc="best", framealpha=0.8, handlelength=1.6, borderaxespad=0.3)
    if ax_s is not None:
        _slip_panel(ax_s, v.series, xlabel)
        ax.tick_params(labelbottom=False)
        ax.set_xlabel("")
        ax_s.tick_params(labelsize=7)
        ax_s.xaxis.label.set_size(8)
        ax_s.yaxis.label.set_size(8)
    else:
        ax.set_xlabel(xlabel, fontsize=8)


def _place(fig, panels, axw, axh, slip_h, under, title) -> None:
    """Size the figure and place every axes at fixed inches as the drawn panels measure (no layout engine, one
    draw): columns as wide as their widest y axis needs on the left and legend or title on the right, rows as
    tall as their titles above and their x axes below."""
    renderer = fig.canvas.get_renderer()
    dpi = fig.dpi

    def room(ax):  # inches the axes' labels, ticks and title reach beyond it: left, right, top, bottom
        box, tight = ax.get_window_extent(renderer), ax.get_tightbbox(renderer)
        return (max(0.0, box.x0 - tight.x0) / dpi, max(0.0, tight.x1 - box.x1) / dpi,
                max(0.0, tight.y1 - box.y1) / dpi, max(0.0, box.y0 - tight.y0) / dpi)

    rooms = {id(a): room(a) for _, _, ax, ax_s in panels for a in (ax, ax_s) if a is not None and a.axison}
    zero = (0.0, 0.0, 0.0, 0.0)
    ncols, nrows = max(j for _, j, _, _ in panels) + 1, max(r for r, _, _, _ in panels) + 1
    left = [max((rooms.get(id(a), zero)[0] for _, j, ax, ax_s in panels if j == c for a in (ax, ax_s) if a), default=0)
            for c in range(ncols)]
    right = [max((rooms.get(id(a), zero)[1] for _, j, ax, ax_s in panels if j == c for a in (ax, ax_s) if a),
                 default=0) for c in range(ncols)]
    top = [max((rooms.get(id(ax), zero)[2] for r, _, ax, _ in panels if r == k), default=0) for k in range(nrows)]
    slips = [any(ax_s is not None for r, _, _, ax_s in panels if r == k) for k in range(nrows)]
    bottom = [max((rooms.get(id(ax_s if ax_s is not None else ax), zero)[3] for r, _, ax, ax_s in panels if r == k),
                  default=0) for k in range(nrows)]
    xs, x = [], base.EDGE
    for c in range(ncols):
        xs.append(x + left[c])
        x = xs[-1] + axw + right[c] + base.GAP
    ys, y = [], base.EDGE + base._lines_in(title, 10) + 0.06
    for k in range(nrows):
        ys.append(y + top[k])
        y = ys[-1] + axh + ((under + slip_h) if slips[k] else 0.0) + bottom[k] + base.GAP
    w, h = x - base.GAP + base.EDGE, y - base.GAP + base.EDGE
    fig.set_size_inches(w, h)
    fig.suptitle(title, fontsize=10, y=1 - base.EDGE / h)
    for r, j, ax, ax_s in panels:
        ax.set_position(_box(fig, xs[j], ys[r], axw, axh))
        if ax_s is not None:
            ax_s.set_position(_box(fig, xs[j], ys[r] + axh + under, axw, slip_h))


def _box(fig, left: float, top: float, width: float, height: float) -> list[float]:
    """An axes rectangle in figure fractions from inches: ``left`` and ``top`` from the figure's top-left corner."""
    w, h = fig.get_size_inches()
    return [left / w, 1 - (top + height) / h, width / w, height / h]


#: In the small panels of the first screen a curve within this fraction of the data's span of a higher-ranked
#: one at every data point cannot be told from it (about two pixels of a 150-pixel panel): drawn once.
MERGED = 0.015


def _merged(curves, span: float) -> list:
    """The curves (fit, label, style) that can be seen apart; one lying under a higher-ranked curve is not
    drawn and is named in that curve's legend entry ('(hides #3 wear [exact])')."""
    out: list = []
    for f, label, style in curves:
        m = f.per_dataset[0].model
        for k, (g, glabel, gstyle) in enumerate(out):
            mg = g.per_dataset[0].model
            if span > 0 and mg.shape == m.shape and np.all(np.abs(mg - m) <= MERGED * span):
                out[k] = (g, f"{glabel} (hides {label.split(', ')[0]})", gstyle)
                break
        else:
            out.append((f, label, style))
    return out


def _against_time(ax, d, target, curves) -> str:
    """The fitted column against time with each fit's dense curve; returns the time axis' label."""
    tname, tf = time_unit(float(d.t[-1]))
    obs = target.observable
    if obs == "stated":  # fitted on a few stated numbers: the noise-free curve drawn through them, for the eye only
        obs = "omega" if "omega" in d.columns else d.observable
        uname, uf = unit(obs)
        ax.plot(d.t * tf, d.columns[obs] * uf, color="0.6", lw=3, alpha=0.6,
                label=f"{d.provenance.kind} curve (figure only, not fitted)", zorder=1)
    else:
        uname, uf = unit(obs)
        y, sigma = target.y, np.broadcast_to(target.sigma, target.y.shape)
        k = base.thinned(target.t, y, y - sigma, y + sigma)  # a long record: what its pixels show
        ax.errorbar(target.t[k] * tf, y[k] * uf, yerr=sigma[k] * uf, fmt="o", ms=3, color="black",
                      ecolor="0.75", elinewidth=0.7, label=f"data ({d.provenance.kind})", zorder=1)
    for f, label, style in curves:
        base.draw_fit(ax, f, obs, d.t, tf, uf, label, **style)
    name = NAMES.get(obs, obs.replace("_", " ")).split(" (")[0]  # the short name: the panel is small
    ax.set_ylabel(f"{name} [{uname}]")
    return f"time [{tname}]"


def _slip_panel(ax, s, xlabel: str):
    """The slip u(t) of the truncated series and of the exact (or ODE) fit of the same law (a SeriesFinding)."""
    tname, tf = time_unit(float(s.dataset.t[-1]))
    t = np.linspace(0.0, float(s.dataset.t[-1]), 300)
    for i, fit in enumerate((s.full, s.series)):  # styled as in the panel above: the series dashed
        tr = base.trajectory(fit.per_dataset[0], fit.law, t)
        ax.plot(t * tf, tr["u"], label=f"{fit.law} [{fit.solver}]", **base._style(fit.law, fit.solver, i))
    ax.axhline(0, color="0.3", lw=0.8)
    if s.t_cross is not None:
        ax.axvline(s.t_cross * tf, color="#d95f02", ls=":", lw=1.3)
    ax.set_ylabel("slip u [m/s]")
    ax.set_xlabel(xlabel)
    ax.legend(fontsize=6.5, loc="best")
    ax.grid(alpha=0.3)
