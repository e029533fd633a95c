"""Fits over data: a time series with residuals, impact-outcome rows, and the force history of each fit."""
from __future__ import annotations

import numpy as np

from ...core.display import NAMES, time_unit, unit
from ...core.errors import FrictionLabError
from . import base


def fit_figure(dataset, fits, rows) -> bytes:
    """Data with every distinct best fit (top) and residuals model - data with the ±1 sigma band (bottom).
    Laws whose fits are the same curve (one functional form) are one entry; a dataset without time
    (rows are impacts) goes to ``outcome_figure``."""
    if "t" not in dataset.columns:
        return outcome_figure(dataset, fits, rows)
    curves = base.distinct_curves(fits)
    if curves and curves[0][0].per_dataset[0].target.observable == "stated":
        from .stated import stated_figure

        return stated_figure(dataset, curves, rows)
    target = curves[0][0].per_dataset[0].target if curves else None
    obs = target.observable if curves else dataset.observable
    uname, uf = unit(obs)
    t = dataset.t
    tname, tf = time_unit(float(t[-1]))
    fig, ((ax,), (axr,)) = base.subplots("fit", 2, 1, figsize=(7.6, 6.0), sharex=True,
                                         gridspec_kw={"height_ratios": [3, 1.6]})
    y = target.y if curves else dataset.columns[obs]
    sigma = target.sigma if curves else np.full(t.shape, dataset.noise.get(obs, np.nan))
    kind = dataset.provenance.kind
    visible = base.visible_curves(curves, float(np.ptp(y)))
    sigma = np.broadcast_to(sigma, t.shape)
    k = base.thinned(t, y, y - sigma, y + sigma, *(f.per_dataset[0].residual for f, _, _ in visible))  # a long record
    ax.errorbar(t[k] * tf, y[k] * uf, yerr=sigma[k] * uf, fmt="o", ms=3.2, color="black", ecolor="0.7", elinewidth=0.8,
                  label=f"data ({kind})" + (f", {target.derivation}" if curves and target.derivation else ""), zorder=1)
    for i, (f, laws, hidden) in enumerate(visible):
        d = f.per_dataset[0]
        style = base._style(f.law, f.solver, i)
        base.draw_fit(ax, f, obs, t, tf, uf, base._label(f, rows, laws, hidden), **style)
        axr.plot(t[k] * tf, d.residual[k] * uf, marker=".", ms=3, **style)
    axr.fill_between(t[k] * tf, -sigma[k] * uf, sigma[k] * uf, color="0.85", label="±1σ noise", zorder=0)
    axr.axhline(0, color="0.3", lw=0.8)
    ax.set_ylabel(f"{NAMES.get(obs, obs)} [{uname}]")
    axr.set_ylabel(f"model − data [{uname}]")
    axr.set_xlabel(f"time [{tname}]")
    title = base.wrapped(f"{dataset.name}: fits of every law" + ("" if kind == "measured" else f"  ({kind} data)"),
                         6.7, 12)
    ax.set_title(title)
    ax.legend(fontsize=8, loc="best", framealpha=0.9)
    axr.legend(fontsize=8, loc="best")
    for a in (ax, axr):
        a.grid(alpha=0.3)
    _residual_limits(axr, [f.per_dataset[0].residual * uf for f, _ in curves], sigma * uf)
    base.margins(fig, top=base.EDGE + base.title_in(title, 12), bottom=base.XAXIS + base.EDGE, hspace=base.GAP)
    return base._png(fig)


def column_unit(dataset, name: str) -> tuple[str, float]:
    """(unit, factor from SI) of column ``name`` as the dataset's file gives it ('' for a plain number)."""
    from ...core.units import unit_factor
    from ...io.dataset import COLUMN_SI

    u = dataset.units.get(name, "")
    si = COLUMN_SI.get(name, "")
    try:
        return u, 1.0 / unit_factor(u, si, name)
    except Exception:  # an odd unit string: show SI
        return si, 1.0


def outcome_figure(dataset, fits, rows) -> bytes:
    """Impact-outcome rows: each distinct fit's prediction against the observation (left) and the
    observation against impact angle (right; one line per group of the other inputs, e.g. speed,
    never joining different groups), in the dataset's own units."""
    obs = dataset.observable
    uname, uf = column_unit(dataset, obs)
    ylab = f"{obs.replace('_', ' ')}" + (f" [{uname}]" if uname else "")
    y = dataset.columns[obs] * uf
    curves = base.visible_curves(base.distinct_curves(fits), float(np.ptp(dataset.columns[obs])))
    sigma = dataset.noise.get(obs, 0.0) * uf
    angle = angle_column(dataset)
    fig, ((axp, axa),) = base.subplots("outcome", 1, 2, figsize=(11.0, 5.2),
                                       gridspec_kw={"width_ratios": [1, 1.35]})
    lo, hi = float(np.min(y)), float(np.max(y))
    for i, (f, laws, hidden) in enumerate(curves):
        st = base._style(f.law, f.solver, i)
        axp.plot(y, f.per_dataset[0].model * uf, "o", ms=4, color=st["color"], alpha=0.85,
                 label=base._label(f, rows, laws, hidden))
        lo, hi = min(lo, float(np.min(f.per_dataset[0].model * uf))), max(hi, float(np.max(f.per_dataset[0].model * uf)))
    pad = 0.05 * (hi - lo or 1.0)
    axp.plot([lo - pad, hi + pad], [lo - pad, hi + pad], color="0.3", lw=0.9, label="predicted = observed")
    axp.set_xlabel(f"observed {ylab}")
    axp.set_ylabel(f"predicted {ylab}")
    axp.set_title("predicted against observed", fontsize=10)
    axp.legend(fontsize=7.5)
    below = base.XAXIS
    if angle is not None:
        against_angle(axa, dataset, [(f, base._label(f, rows, laws, hidden), base._style(f.law, f.solver, i))
                                     for i, (f, laws, hidden) in enumerate(curves)])
        below = base.legend_below(axa, fontsize=7, ncol=2)
    else:
        axa.set_visible(False)
    for a in (axp, axa):
        a.grid(alpha=0.3)
    kind = dataset.provenance.kind
    title = base.wrapped(f"{dataset.name}: fits of every law" + ("" if kind == "measured" else f"  ({kind} data)"),
                         10.7, 11)
    base.margins(fig, top=base.suptitle(fig, title, 11) + base.title_in(axa.get_title() or axp.get_title(), 10),
                 bottom=below + base.EDGE)
    return base._png(fig)


def angle_column(dataset) -> str | None:
    """The impact-angle input column of an impact-outcome dataset (None without one)."""
    return next((c for c in dataset.columns if c != dataset.observable and c in ("incidence", "angle")), None)


def against_angle(ax, dataset, curves):
    """The observable against impact angle, one line per group of the other inputs (e.g. speed; never
    joining different groups); ``curves``: (fit, legend label, style) drawn through each group's rows."""
    obs, angle = dataset.observable, angle_column(dataset)
    uname, uf = column_unit(dataset, obs)
    y, sigma = dataset.columns[obs] * uf, dataset.noise.get(obs, 0.0) * uf
    others = [c for c in dataset.columns if c not in (obs, angle) and c in ("speed", "spin")
              and len(np.unique(dataset.columns[c])) > 1]
    au, af = column_unit(dataset, angle)
    x = dataset.columns[angle] * af
    keys = [tuple(dataset.columns[c][k] for c in others) for k in range(len(dataset))]
    markers = "osD^v<>"
    for gi, key in enumerate(dict.fromkeys(keys)):
        idx = np.array([k for k in range(len(dataset)) if keys[k] == key])
        idx = idx[np.argsort(x[idx], kind="stable")]
        glabel = ", ".join(f"{c} {key[j] * column_unit(dataset, c)[1]:.3g} {column_unit(dataset, c)[0]}"
                           for j, c in enumerate(others))
        ax.errorbar(x[idx], y[idx], yerr=sigma, fmt=markers[gi % len(markers)], ms=4, color="black",
                    ecolor="0.7", elinewidth=0.7, zorder=1,
                    label=f"data: {glabel}" if glabel else f"data ({dataset.provenance.kind})")
        for f, label, st in curves:
            ax.plot(x[idx], f.per_dataset[0].model[idx] * uf, color=st["color"], ls=st["ls"], lw=1.4,
                    label=label if gi == 0 else None, zorder=2)
    ylab = f"{obs.replace('_', ' ')}" + (f" [{uname}]" if uname else "")
    ax.set_xlabel(f"{angle} [{au}]")
    ax.set_ylabel(ylab)
    ax.set_title(f"against {angle}" + (f", one line per {' and '.join(others)}" if others else ""), fontsize=10)


def _residual_limits(ax, residuals, sigma):
    """Show all residuals, but never shrink below the noise band."""
    if not residuals:
        return
    top = max(float(np.max(np.abs(r))) for r in residuals)
    top = max(top, 1.5 * float(np.max(sigma)))
    ax.set_ylim(-1.08 * top, 1.08 * top)


def force_figure(dataset, fits, rows=()) -> bytes:
    """The friction force history of every law's best fit."""
    curves = [(f, laws) for f, laws in base.distinct_curves(fits) if f.per_dataset[0].target.t is not None]
    span = float(np.ptp(curves[0][0].per_dataset[0].target.y)) if curves else 1.0
    curves = base.visible_curves(curves, span)  # a force history under another's: named in its entry
    t_end = float(dataset.t[-1])
    tname, tf = time_unit(t_end)
    fig, ((ax,),) = base.subplots("force", figsize=(7.6, 3.8))
    drawn = 0
    for i, (f, laws, hidden) in enumerate(curves):
        try:
            tr = base.trajectory(f.per_dataset[0], f.law, np.linspace(0.0, t_end, 300))
        except FrictionLabError:  # a stiff law whose dense curve exceeds the solver's budget: left out
            continue
        ax.plot(tr.t * tf, tr.force, label=base._label(f, rows, laws, hidden), **base._style(f.law, f.solver, i))
        drawn += 1
    ax.axhline(0, color="0.3", lw=0.8)
    ax.set_xlabel(f"time [{tname}]")
    ax.set_ylabel("friction force F [N] (positive opposes slip)")
    title = base.wrapped(f"{dataset.name}: friction force of each best fit", 6.7, 12)
    ax.set_title(title)
    ax.grid(alpha=0.3)
    if drawn:
        ax.legend(fontsize=8)
    else:
        ax.text(0.5, 0.5, "no fit's force history could be drawn\n(each exceeded the solver's budget)",
                transform=ax.transAxes, ha="center", va="center", color="0.3")
    base.margins(fig, top=base.EDGE + base.title_in(title, 12), bottom=base.XAXIS + base.EDGE)
    return base._png(fig)
