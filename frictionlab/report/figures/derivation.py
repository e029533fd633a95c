"""Spin derived from the rotation angle, by each route, with and without camera noise."""
from __future__ import annotations

import numpy as np

from ...core.display import time_unit, unit
from . import base


def derivation_figure(dataset, derived: dict, noisy: dict, sigma_theta: float, seed: int) -> bytes:
    """What each theta -> omega route does: on the theta column as given (left) and, where a sigma of
    theta is known (> 0), on the same column with simulated camera noise of that sigma (right)."""
    t = dataset.t
    tname, tf = time_unit(float(t[-1]))
    du, df = unit("omega")
    au, af = unit("theta")
    views = [("theta column as given", derived)]
    if sigma_theta > 0:  # a noise-free column (no stated sigma): the noisy twin would repeat it
        views.append((f"with simulated noise σθ = {sigma_theta * af:.2g} {au} (seed {seed})", noisy))
    width = 5.25 * len(views) + (0 if sigma_theta > 0 else 1.0)
    fig, axes = base.subplots("derive", 2, len(views), figsize=(width, 6.6), sharex=True)
    colors = {"poly9": "#d95f02", "spline": "#1b9e77"}
    for col, (title, res) in enumerate(views):
        ax, axw = axes[0, col], axes[1, col]
        source = dataset.columns["theta"] if col == 0 else noisy["_theta"]
        ax.plot(t * tf, source * af, "o", ms=3, color="black", label="theta used")
        for name, d in res.items():
            if name.startswith("_"):
                continue
            ax.plot(t * tf, d.theta_fit * af, color=colors.get(name), lw=1.5, label=f"{name} fit")
            axw.plot(t * tf, d.omega * df, color=colors.get(name), lw=1.5, label=f"omega from {name}")
            if col == 1:  # the column as given is noise-free: a band would only show the stated sigma
                axw.fill_between(t * tf, (d.omega - d.sigma) * df, (d.omega + d.sigma) * df,
                                 color=colors.get(name), alpha=0.15)
        if "omega" in dataset.columns:
            axw.plot(t * tf, dataset.columns["omega"] * df, "k.", ms=4, label="omega column")
        ax.set_title(title, fontsize=10)
        ax.set_ylabel(f"theta [{au}]")
        axw.set_ylabel(f"omega [{du}]")
        axw.set_xlabel(f"time [{tname}]")
        for a in (ax, axw):
            a.grid(alpha=0.3)
            a.legend(fontsize=7)
        finite = [d.omega * df for k, d in res.items() if not k.startswith("_")]
        if "omega" in dataset.columns:
            ref = dataset.columns["omega"] * df
            span = float(np.max(ref) - np.min(ref)) or 1.0
            lo = min(float(np.min(ref)), min(float(np.percentile(f, 2)) for f in finite)) - 0.15 * span
            hi = max(float(np.max(ref)), max(float(np.percentile(f, 98)) for f in finite)) + 0.15 * span
            axw.set_ylim(lo, hi)
    title = base.wrapped(f"{dataset.name}: spin derived from rotation angle" + (
        " (shaded: ±1σ each route passes on from θ noise)" if sigma_theta > 0 else " (no θ noise stated)"),
        fig.get_figwidth() - 0.3, 11)
    top = base.suptitle(fig, title, 11) + max(base.title_in(ax.get_title(), 10) for ax in axes[0])
    base.margins(fig, top=top, bottom=base.XAXIS + base.EDGE, hspace=base.GAP)
    return base._png(fig)
