"""The first screen's finding: the paper's truncated series against the exact solution."""
from __future__ import annotations

import numpy as np

from ...core.display import time_unit, unit
from . import base


def finding_figure(findings) -> bytes:
    """Per finding (report.first_screen.SeriesFinding), one column: the data's spin with the series and the
    exact fit of the same law (top), the slip u(t) of each (bottom), the series' zero crossing marked."""
    plt = base._plt()
    n = len(findings)
    fig, axes = plt.subplots(2, n, figsize=(4.6 * n + 0.4, 3.7), sharex="col", squeeze=False, layout="constrained",
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
        ax.set_title(f"{d.name}" + ("" if d.provenance.kind == "measured" else f" ({d.provenance.kind} data)"),
                     fontsize=10)
        ax.set_ylabel(f"spin ω [{su}]")
        axu.set_ylabel("slip u [m/s]")
        axu.set_xlabel(f"time [{tname}] (grey line: end of contact t_c)")
        ax.legend(fontsize=7, loc="lower right")
        for a in (ax, axu):
            a.grid(alpha=0.3)
    fig.suptitle("Why the paper's spin falls:" + (" " if n > 1 else "\n") + "its truncated series' slip turns negative; "
                 "the exact solution's never does", fontsize=10.5)
    return base._png(fig)
