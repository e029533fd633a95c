"""The first screen's finding: the paper's truncated series against the exact solution."""
from __future__ import annotations

import numpy as np

from ...core.display import NAMES, time_unit, unit
from . import base


def finding_figure(findings) -> bytes:
    """Per finding (report.first_screen.SeriesFinding), one column: the data's spin with the series and the
    exact fit of the same law (top), the slip u(t) of each (bottom), the series' zero crossing marked."""
    plt = base._plt()
    n = len(findings)
    fig, axes = plt.subplots(2, n, figsize=(4.6 * n + 0.4, 3.7), sharex="col", squeeze=False,
                             gridspec_kw={"height_ratios": [1.5, 1]})
    su, sf = unit("omega")
    for j, f in enumerate(findings):
        d = f.dataset
        ax, axu = axes[0, j], axes[1, j]
        t_end = float(d.t[-1])
        tname, tf = time_unit(t_end)
        t = np.linspace(0.0, t_end, 300)
        obs = f.series.per_dataset[0].target.observable
        if obs == "omega":
            target = f.series.per_dataset[0].target
            ax.errorbar(d.t * tf, target.y * sf, yerr=target.sigma * sf, fmt="o", ms=2.6, color="black",
                        ecolor="0.75", elinewidth=0.7, label=f"data ({d.provenance.kind})", zorder=1)
        elif "omega" in d.columns:  # fitted to another column: the dataset's spin column, as given
            ax.errorbar(d.t * tf, d.columns["omega"] * sf, yerr=d.noise.get("omega", 0.0) * sf, fmt="o", ms=2.6,
                        color="black", ecolor="0.75", elinewidth=0.7, zorder=1,
                        label=f"data ({d.provenance.kind}), spin column")
        for fit, color, ls in ((f.full, "#1b9e77", "-"), (f.series, "#d95f02", "--")):
            tr = fit.per_dataset[0].trajectory(fit.law, t)
            label = f"{fit.law} [{fit.solver}]" + (" (paper's truncated series)" if fit.solver == "series" else "")
            ax.plot(t * tf, tr["omega"] * sf, color=color, ls=ls, lw=2, label=label, zorder=3)
            axu.plot(t * tf, tr["u"], color=color, ls=ls, lw=2, label=label)
        axu.axhline(0, color="0.3", lw=0.8)
        if f.t_cross is not None:
            for a in (ax, axu):
                a.axvline(f.t_cross * tf, color="#d95f02", ls=":", lw=1.3)
            axu.annotate(f"series slip = 0 at {f.t_cross * tf:.0f} {tname}:\nfriction reverses, spin falls",
                         xy=(f.t_cross * tf, 0.0), xytext=(0.03, 0.06), textcoords="axes fraction", fontsize=8,
                         bbox={"fc": "white", "ec": "none", "alpha": 0.85, "pad": 1},
                         arrowprops={"arrowstyle": "->", "color": "0.3"})
        ax.axvline(f.contact_time * tf, color="0.6", lw=0.8)
        axu.axvline(f.contact_time * tf, color="0.6", lw=0.8)
        ax.set_title(base.wrapped(d.name + ("" if d.provenance.kind == "measured" else f" ({d.provenance.kind} data)"),
                                  4.4, 10), fontsize=10)
        ax.set_ylabel(f"spin ω [{su}]")
        axu.set_ylabel("slip u [m/s]")
        axu.set_xlabel(f"time [{tname}] (grey line: end of contact t_c)")
        ax.legend(fontsize=7, loc="lower right")
        for a in (ax, axu):
            a.grid(alpha=0.3)
    title = base.wrapped("Why the paper's spin falls: its truncated series' slip turns negative; the exact solution's "
                         "never does", 4.6 * n + 0.1, 10.5)
    top = base.suptitle(fig, title, 10.5) + max(base.title_in(ax.get_title(), 10) for ax in axes[0])
    base.margins(fig, top=top, bottom=base.XAXIS + base.EDGE, hspace=base.GAP)
    return base._png(fig)


def data_figure(views, title: str) -> bytes:
    """Per view (report.first_screen.DataView), one column: the data with the top-ranked candidates (top)
    and, only where the paper's series was fitted, the slip u(t) of the series and the exact fit (bottom).
    A dataset without time (one impact per row) shows its observable against impact angle."""
    from .fits import against_angle, angle_column

    plt = base._plt()
    n = len(views)
    slips = any(v.series is not None for v in views)
    width = 5.2 * n + 0.6
    fig, axes = plt.subplots(2 if slips else 1, n, figsize=(width, 4.15 if slips else 3.7), squeeze=False,
                             gridspec_kw={"height_ratios": [1.5, 1]} if slips else None)
    below = base.XAXIS
    for j, v in enumerate(views):
        d, ax = v.dataset, axes[0, j]
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
        ax.set_title(base.wrapped(d.name + ("" if d.provenance.kind == "measured" else f" ({d.provenance.kind} data)"),
                                  5.0, 10), fontsize=10)
        ax.grid(alpha=0.3)
        if slips:
            _slip_panel(axes[1, j], v.series, xlabel) if v.series is not None else axes[1, j].set_axis_off()
        if not slips or v.series is None:
            ax.set_xlabel(xlabel)
        else:  # the slip panel below carries the time axis
            ax.tick_params(labelbottom=False)
        below = max(below, base.legend_below(ax, base.XAXIS if ax.get_xlabel() else 0.1, fontsize=7, ncol=2))
    title = base.wrapped(title, width - 0.3, 10.5)
    top = base.suptitle(fig, title, 10.5) + max(base.title_in(ax.get_title(), 10) for ax in axes[0])
    if slips:  # the legends between the rows, the slip panels' time axes at the bottom
        base.margins(fig, top=top, bottom=base.XAXIS + base.EDGE, hspace=below + base.GAP)
    else:
        base.margins(fig, top=top, bottom=below + base.EDGE)
    return base._png(fig)


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
    """The slip u(t) of the paper's series and of the exact (or ODE) fit of the same law (a SeriesFinding)."""
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
    ax.legend(fontsize=7, loc="best")
    ax.grid(alpha=0.3)
