"""What a fit and a ranking draw in a notebook: the data, each candidate's best fit, and its residuals in
units of sigma (``FitResult.plot``; ``Comparison.plot`` in the pipeline draws its groups with these).

Units: each series in the unit its dataset's file gives it (``Dataset.shown``). A reconstruction fitted to
its stated numbers shows each number and each fit's value relative to that number, since the numbers
differ in kind (a spin, a time, an angle).
"""
from __future__ import annotations

import numbers

import numpy as np

from ...core.display import axis_label, check_axes, figure_axes

#: Colours of the candidates, in rank order (colour-blind safe, as the report's).
COLORS = ("#1b9e77", "#d95f02", "#7570b3", "#e7298a", "#66a61e", "#e6ab02")


def _axis(target) -> tuple[np.ndarray, str, list[str] | None]:
    """(x values, x label, tick labels or None) of a fitted series."""
    d = target.dataset
    if target.observable == "stated":
        names = list(d.stated)
        return np.arange(len(names), dtype=float), "stated number", names
    xcol, xunit, xf = d.x_axis()
    if not xcol:
        return np.arange(target.y.size, dtype=float), "row", None
    return d.columns[xcol] * xf, axis_label({"t": "time"}.get(xcol, xcol), xunit), None


def _scale(target) -> tuple[np.ndarray, str]:
    """(factor per point, y label): the dataset's unit for its observable, or 1 / stated value."""
    if target.observable == "stated":
        return 1.0 / np.where(target.y != 0, target.y, 1.0), "relative to the stated value [-]"
    shown, f = target.dataset.shown(target.observable)
    return np.full(target.y.size, f), axis_label(target.observable, shown)


def draw_data(ax, target) -> None:
    """The fitted series of ``target`` with its sigma as error bars."""
    x, xlabel, ticks = _axis(target)
    f, ylabel = _scale(target)
    sigma = np.where(np.isfinite(target.sigma), target.sigma, 0.0) * f
    ax.errorbar(x, target.y * f, yerr=sigma, fmt="o", ms=3, color="black", ecolor="0.7", elinewidth=0.8,
                label=f"{target.label}: {target.dataset.provenance.kind}", zorder=1)
    ax.set_ylabel(ylabel)
    if ticks:
        ax.set_xticks(x, ticks, rotation=15, fontsize=8)
    ax.grid(alpha=0.3)


def draw_fit(ax, ax_res, dataset_fit, label: str, color: str) -> None:
    """One candidate's best fit on ``ax`` and its residuals (model - data) / sigma on ``ax_res`` (None: none)."""
    target = dataset_fit.target
    x, xlabel, _ = _axis(target)
    f, _ = _scale(target)
    order = np.argsort(x, kind="stable")
    # a curve through a time series, a dashed one through outcomes against angle, points for stated numbers
    line = "none" if target.observable == "stated" else "-" if target.dataset.x_axis()[0] == "t" else "--"
    ax.plot(x[order], (dataset_fit.model * f)[order], ls=line, marker="" if line == "-" else "s", ms=5,
            color=color, lw=1.8, label=label, zorder=3)
    if ax_res is not None:
        z = dataset_fit.residual / np.where(np.isfinite(target.sigma) & (target.sigma > 0), target.sigma, np.nan)
        ax_res.plot(x[order], z[order], "o-", ms=2.5, lw=0.8, color=color)
        ax_res.axhline(0.0, color="0.3", lw=0.8)
        ax_res.set_ylabel("residual / sigma")
        ax_res.set_xlabel(xlabel)
        ax_res.grid(alpha=0.3)
    else:
        ax.set_xlabel(xlabel)


def fits_text(goodness) -> str:
    """'yes', 'no (chi2 p = 1e-9)' or 'not tested': whether a fit passes its goodness-of-fit tests."""
    if goodness is None or goodness.fits is None:
        return "not tested"
    return "yes" if goodness.fits else f"no ({goodness.text})" if goodness.text else "no"


def fit_label(result) -> str:
    """The legend entry of a fit: law, solver and whether it fits."""
    return f"{result.law} [{result.solver}]: fits? {fits_text(result.goodness)}"


def plot_fit(result, ax=None):
    """FitResult.plot: per fitted dataset, the data with the best fit above and the residuals below; with
    ``ax`` (one Axes, or one per dataset) the data and fit only. Returns the Figure, or ``ax`` when given."""
    if not result.ok:
        raise ValueError(f"{result.law} on {', '.join(result.datasets)}: {result.status}, nothing to plot "
                         f"({result.reason})")
    per = result.per_dataset
    if ax is not None:
        axes = check_axes(ax, "FitResult.plot", many=True)
        if len(axes) != len(per):
            raise ValueError(f"plot: {len(per)} datasets need {len(per)} axes, got {len(axes)}")
        for a, d in zip(axes, per):
            draw_data(a, d.target)
            draw_fit(a, None, d, fit_label(result), COLORS[0])
            a.legend(fontsize=8)
        return ax
    fig, axes = figure_axes(None, 2, len(per), size=(6.0 * len(per), 5.6), sharex="col",
                            gridspec_kw={"height_ratios": [2.2, 1]})
    axes = np.asarray(axes).reshape(2, len(per))
    for j, d in enumerate(per):
        draw_data(axes[0, j], d.target)
        draw_fit(axes[0, j], axes[1, j], d, fit_label(result), COLORS[0])
        axes[0, j].legend(fontsize=8)
        axes[0, j].set_title(d.name, fontsize=10)
    fig.tight_layout()
    return fig


def plot_ranking(panels, ax=None, top: int = 3):
    """Comparison.plot's drawing: ``panels`` is a list of (title, dataset fits of the top-ranked candidates
    with their labels); one column each, data and fits above, residuals below. Returns the Figure, or
    ``ax`` (one Axes per panel: data and fits only) when given."""
    if isinstance(top, bool) or not isinstance(top, numbers.Integral) or top < 1:
        raise ValueError(f"Comparison.plot: top: expected a whole number of candidates, at least 1, got {top!r:.40}")
    if not panels:
        raise ValueError("plot: no fitted dataset to draw")
    if ax is not None:
        axes = check_axes(ax, "Comparison.plot", many=True)
        if len(axes) != len(panels):
            raise ValueError(f"plot: {len(panels)} dataset groups need {len(panels)} axes, got {len(axes)}")
        grid = None
    else:
        fig, grid = figure_axes(None, 2, len(panels), size=(5.6 * len(panels), 5.6), sharex="col",
                                gridspec_kw={"height_ratios": [2.2, 1]})
        grid = np.asarray(grid).reshape(2, len(panels))
        axes = list(grid[0])
    for j, (title, fits) in enumerate(panels):
        a = axes[j]
        draw_data(a, fits[0][0].target)
        for i, (dataset_fit, label) in enumerate(fits[:top]):
            draw_fit(a, None if grid is None else grid[1, j], dataset_fit, label, COLORS[i % len(COLORS)])
        a.set_title(title, fontsize=10)
        a.legend(fontsize=7)
    if grid is None:
        return ax
    fig.tight_layout()
    return fig
