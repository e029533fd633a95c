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
    fig, ax = plt.subplots(figsize=(1.25 * len(datasets) + 3.2, 0.55 * len(cands) + 1.8), layout="constrained")
    cmap = plt.get_cmap("viridis_r").with_extremes(bad="0.9")
    im = ax.imshow(np.where(np.isnan(M), np.nan, M + 1.0), cmap=cmap, aspect="auto",
                   norm=LogNorm(vmin=1.0, vmax=max(10.0, np.nanmax(M + 1.0) if np.isfinite(M).any() else 10.0)))
    for i in range(len(cands)):
        for j in range(len(datasets)):
            dark = np.isfinite(M[i, j]) and M[i, j] + 1 > 30
            ax.text(j, i, text[i][j], ha="center", va="center", fontsize=7, color="white" if dark else "black")
    ax.set_xticks(range(len(datasets)), datasets, rotation=35, ha="right", fontsize=8)
    ax.set_yticks(range(len(cands)), cands, fontsize=8)
    cb = fig.colorbar(im, ax=ax, shrink=0.85)
    cb.set_label("ΔAIC + 1 (log scale; 1 = best)")
    plain_log(cb.ax.yaxis)
    ax.set_title(base.wrapped("Ranking per dataset: #rank and ΔAIC (solver exact unless named)",
                              fig.get_figwidth() - 1.2, 12), fontsize=12)
    return base._png(fig)
