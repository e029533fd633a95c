"""The first screen's figure: each dataset group's data with its top-ranked candidates, and the slip of the
truncated series against the exact solution where that series is among them."""
from __future__ import annotations

import numpy as np

from ...core.display import NAMES, time_unit, unit
from . import base


def group_figure(views, title: str) -> bytes:
    """The first screen's figure: per view (report.data_view.DataView: one dataset of a group with the group's
    top-ranked candidates) one panel, PER_ROW to a row, and under a panel whose candidates include the
    truncated series, the slip u(t) of that series and of the exact fit of the same law. A dataset without time
    (one impact per row) shows its observable against impact angle."""
    from ..data_view import PER_ROW
    from .fits import against_angle, angle_column

    plt = base._plt()
    n = len(views)
    cols = min(n, PER_ROW)
    rows = [views[k:k + cols] for k in range(0, n, cols)]
    panel_w = {1: 5.4, 2: 4.4}.get(cols, 3.1)  # inches: few panels are drawn larger, five fill the page's width
    panel_h, slip_h = 1.75 + 0.25 * (panel_w - 3.1), 0.85
    head = 0.3  # a panel's title above the axes
    below = base.XAXIS + base.GAP
    heights = [head + panel_h + below + ((slip_h + base.GAP) if any(v.series for v in row) else 0.0) for row in rows]
    width = panel_w * cols + 0.5
    title = base.wrapped(title, width - 0.3, 10)
    top = base.EDGE + base._lines_in(title, 10) + 0.1
    fig = plt.figure(figsize=(width, top + sum(heights) + base.EDGE))
    fig.set_dpi(base.DPI)
    fig.suptitle(title, fontsize=10, y=1 - base.EDGE / fig.get_figheight())
    y = top
    for row, h in zip(rows, heights):
        slips = any(v.series for v in row)
        for j, v in enumerate(row):
            left = 0.55 + j * panel_w
            ax = fig.add_axes(_box(fig, left, y + head, panel_w - 0.7, panel_h))
            ax_s = fig.add_axes(_box(fig, left, y + head + panel_h + 0.08, panel_w - 0.7, slip_h)) \
                if slips and v.series is not None else None
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
                continue
            name = v.group + ("" if v.group == d.name else f": {d.name}")
            ax.set_title(base.wrapped(name + ("" if d.provenance.kind == "measured" else f" ({d.provenance.kind})"),
                                      panel_w - 0.6, 9), fontsize=9, pad=2)
            ax.grid(alpha=0.3)
            ax.tick_params(labelsize=7)
            ax.yaxis.label.set_size(8)
            ax.legend(fontsize=6.5, loc="best", framealpha=0.8, handlelength=1.6, borderaxespad=0.3)
            if ax_s is not None:
                _slip_panel(ax_s, v.series, xlabel)
                ax.tick_params(labelbottom=False)
                ax_s.tick_params(labelsize=7)
                ax_s.xaxis.label.set_size(8)
                ax_s.yaxis.label.set_size(8)
            else:
                ax.set_xlabel(xlabel, fontsize=8)
        y += h
    return base._png(fig)


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
        ax.errorbar(target.t * tf, target.y * uf, yerr=target.sigma * uf, fmt="o", ms=3, color="black",
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
        tr = fit.per_dataset[0].trajectory(fit.law, t)
        ax.plot(t * tf, tr["u"], label=f"{fit.law} [{fit.solver}]", **base._style(fit.law, fit.solver, i))
    ax.axhline(0, color="0.3", lw=0.8)
    if s.t_cross is not None:
        ax.axvline(s.t_cross * tf, color="#d95f02", ls=":", lw=1.3)
    ax.set_ylabel("slip u [m/s]")
    ax.set_xlabel(xlabel)
    ax.legend(fontsize=6.5, loc="best")
    ax.grid(alpha=0.3)
