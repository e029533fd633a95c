"""A measured velocity step: the data with the fitted law (whole record, and the first step close up), the
residuals, and the fitted parameters with their intervals in laboratory units beside them."""
from __future__ import annotations

import textwrap

import numpy as np

from . import base

#: Parameters in the figure's table, in order, with their display names.
ROWS = (("a", "a"), ("b", "b"), ("a-b", "a − b"), ("Dc", "Dc"), ("k", "k"), ("mu0", "μ0"), ("trend", "trend"))


def velstep_figure(fit) -> bytes:
    """Data and fit (left: the record; middle: the first step close up), residuals below, and the parameter table
    (value ± standard error, 95% interval) on the right, for a velocity-step fit of one dataset."""
    d = fit.per_dataset[0]
    t, y, model = d.target.t, d.target.y, d.model
    steps = d.scene.spring.times[1:]
    t0 = steps[0] if steps else 0.0
    fig, (ax, axz, axr, axrz, axt) = base.canvas(("velstep",), (11.0, 4.2), _panels)
    every = max(1, t.size // 4000)  # at most about 4000 points drawn per panel
    color = base.EXTRA_COLORS[4]
    for a, ar, sel in ((ax, axr, slice(None, None, every)), (axz, axrz, _close_up(t, steps, fit))):
        a.plot(t[sel] - t0, y[sel], ".", ms=1.6, color="0.45", label="data (measured)", rasterized=True)
        a.plot(t[sel] - t0, model[sel], "-", lw=1.4, color=color, label=f"{fit.law} fit")
        ar.plot(t[sel] - t0, (model - y)[sel], ".", ms=1.2, color="0.45", rasterized=True)
        ar.axhline(0.0, color=color, lw=0.8)
        for s in steps:
            for b in (a, ar):
                b.axvline(s - t0, color="0.7", lw=0.6, ls=":")
        a.tick_params(labelbottom=False)
        a.grid(alpha=0.3)
        ar.grid(alpha=0.3)
    ax.set_ylabel("friction μ")
    axr.set_ylabel("fit − data")
    axr.set_xlabel("time from the step [s]")
    axrz.set_xlabel("close up [s]")
    ax.legend(fontsize=7, loc="best", markerscale=4)
    ax.set_title(base.wrapped(f"{d.target.name}: {fit.law}", 6.0, 10), fontsize=10)
    axt.axis("off")
    axt.text(0.0, 1.0, _table_text(fit), family="monospace", fontsize=7.6, va="top", ha="left",
             transform=axt.transAxes)
    fig.subplots_adjust(left=0.085, right=0.99, top=0.9, bottom=0.13)
    return base._png(fig)


def _panels(fig) -> tuple:
    """The figure's axes: the record and the close up (top), their residuals (under them), the table (right)."""
    grid = fig.add_gridspec(2, 3, width_ratios=[1.5, 1.0, 1.05], height_ratios=[2.2, 1.0], wspace=0.28, hspace=0.08)
    ax, axz, axr = fig.add_subplot(grid[0, 0]), fig.add_subplot(grid[0, 1]), fig.add_subplot(grid[1, 0])
    return ax, axz, axr, fig.add_subplot(grid[1, 1], sharex=axz), fig.add_subplot(grid[:, 2])


def _close_up(t, steps, fit) -> np.ndarray:
    """Indices from a little before the first step to where the transient has run its course (5 Dc of slip, at
    least 20 samples)."""
    if not steps:
        return np.arange(min(t.size, 2000))
    q = fit.velstep.rows[0].quantities
    V2 = fit.velstep.rows[0].steps[0][1] if fit.velstep.rows[0].steps else 1.0
    span = max(5 * q["Dc"].value / max(V2, 1e-12), 0.0)
    i0 = int(np.searchsorted(t, steps[0]))
    i1 = max(int(np.searchsorted(t, steps[0] + span)), i0 + 20)
    lead = max(10, (i1 - i0) // 5)
    return np.arange(max(i0 - lead, 0), min(i1, t.size))


def _table_text(fit) -> str:
    """The parameter table, one line each: name, value ± standard error, 95% interval, unit."""
    row = fit.velstep.rows[0]
    lines = ["value ± s.e.  [95% interval]", ""]
    for key, name in ROWS:
        q = row.quantities.get(key)
        if q is None:
            continue
        unit = f" {q.unit.replace('um', 'µm')}" if q.unit else ""
        if q.stderr is None:
            lines.append(f"{name:<6}{q.value:.4g}{unit}  ({q.missing})")
        else:
            d = q.digits
            lines.append(f"{name:<6}{q.value:.{d}g} ± {q.stderr:.2g}{unit}")
            lines.append(f"{'':<6}[{q.low:.{d}g}, {q.high:.{d}g}]")
    for label, phi in row.phi:
        lines.append(f"φ {label}: {phi:.3f}")
    for label, model in row.noise:
        lines += textwrap.wrap(f"noise {label}: {model}", 34, subsequent_indent="  ")
    lines.append("")
    lines.append(f"goodness: {fit.goodness.short}")
    return "\n".join(lines)
