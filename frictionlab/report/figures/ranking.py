"""The ranking heat map: delta-AIC of every candidate on every dataset."""
from __future__ import annotations

import numpy as np

from ...core.display import plain_log
from . import base


def ranking_figure(rows, alias: dict | None = None) -> bytes:
    """Heat map of delta-AIC, candidates x datasets, with ranks; grey where no fit. ``alias`` maps a law
    to the label it shares with laws of the same curve everywhere ("wear = couette"): one row for them."""
    plt = base._plt()
    from matplotlib.colors import LogNorm

    alias = alias or {}
    datasets = list(dict.fromkeys(r.dataset for r in rows))
    row_of = lambda r: alias.get(r.law, r.law) + (" [series]" if r.solver == "series" else "")  # noqa: E731
    cands = sorted({row_of(r) for r in rows})
    M = np.full((len(cands), len(datasets)), np.nan)
    text = [["" for _ in datasets] for _ in cands]
    for r in rows:
        i, j = cands.index(row_of(r)), datasets.index(r.dataset)
        if r.rank is not None:
            M[i, j] = r.delta_aic
            text[i][j] = f"#{r.rank}\n{r.delta_aic:.1f}" + ("" if r.solver in ("exact", "series") else f"\n{r.solver}")
        else:
            text[i][j] = r.status
    heat = (1.25 * len(datasets) + 0.8, 0.55 * len(cands) + 0.5)  # inches: the heat map; the figure grows around it
    fig = base.figure((heat[0] + 3.2, heat[1] + 1.3))
    ax = fig.subplots()
    cmap = plt.get_cmap("viridis_r").with_extremes(bad="0.9")
    im = ax.imshow(np.where(np.isnan(M), np.nan, M + 1.0), cmap=cmap, aspect="auto",
                   norm=LogNorm(vmin=1.0, vmax=max(10.0, np.nanmax(M + 1.0) if np.isfinite(M).any() else 10.0)))
    for i in range(len(cands)):
        for j in range(len(datasets)):
            dark = np.isfinite(M[i, j]) and M[i, j] + 1 > 30
            ax.text(j, i, text[i][j], ha="center", va="center", fontsize=7, color="white" if dark else "black")
    ax.set_xticks(range(len(datasets)), datasets, rotation=35, ha="right", fontsize=8)
    ax.set_yticks(range(len(cands)), cands, fontsize=8)
    cb = fig.colorbar(im, cax=fig.add_axes((0.0, 0.0, 0.01, 0.5)))  # placed by _place
    cb.set_label("ΔAIC + 1 (log scale; 1 = best)")
    plain_log(cb.ax.yaxis)
    title = base.wrapped("Ranking per dataset: #rank and ΔAIC (solver exact unless named)", heat[0] + 0.4, 12)
    ax.set_title(title, fontsize=12)
    _place(fig, ax, cb.ax, heat, top=base.EDGE + base.title_in(title, 12))
    return base._png(fig)


#: Inches right of the heat map: the gap and the colour bar (its ticks and label are measured).
CBAR_PAD, CBAR = 0.2, 0.35


def _place(fig, ax, cax, heat: tuple[float, float], top: float) -> None:
    """The figure sized to the heat map (``heat``: width, height in inches) and the labels around it, as they
    measure: the candidates left, the slanted dataset names below (and left of the first), the colour bar right."""
    for _ in range(2):  # measured where placed: the slanted names' reach to the left depends on the cell width
        r = fig.canvas.get_renderer()
        box, names, bar = ax.get_window_extent(r), ax.xaxis.get_tightbbox(r), cax.yaxis.get_tightbbox(r)
        left = max([(box.x0 - names.x0) / fig.dpi] + [side for _, side, _ in base.yaxes_in(fig)]) + base.EDGE
        bottom = (box.y0 - names.y0) / fig.dpi + base.EDGE
        right = CBAR + (bar.x1 - cax.get_window_extent(r).x1) / fig.dpi + base.EDGE
        fig.set_size_inches(left + heat[0] + right, top + heat[1] + bottom)
        base.margins(fig, top=top, bottom=bottom, right=right, left=left)
        w = fig.get_figwidth()
        p = ax.get_position()
        cax.set_position((p.x1 + CBAR_PAD / w, p.y0 + 0.075 * p.height, (CBAR - CBAR_PAD) / w, 0.85 * p.height))
