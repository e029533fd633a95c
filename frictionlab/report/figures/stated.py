"""The figure of a reconstruction fitted on its stated numbers (``[noise] kind = "none"``, ``[stated]``)."""
from __future__ import annotations

import numpy as np

from ...core.display import time_unit, unit
from . import base


STATED_LABELS = {"omega_peak": "peak ω", "t_peak": "its time", "omega_end": "ω at t_c", "theta_max": "largest θ"}


def stated_figure(dataset, curves, rows) -> bytes:
    """A reconstruction fitted on its stated numbers: the noise-free spin curve (grey, drawn for the figure
    only) with the stated peak and end-of-contact spin as crosses of their stated precision and each
    distinct fit's spin (top); each stated number's miss (model − stated) / precision (bottom)."""
    t = dataset.t
    tname, tf = time_unit(float(t[-1]))
    uname, uf = unit("omega")
    st = dataset.stated
    fig, ((ax,), (axr,)) = base.subplots("stated", 2, 1, figsize=(7.6, 6.0),
                                         gridspec_kw={"height_ratios": [3, 1.6]})
    if "omega" in dataset.columns:
        ax.plot(t * tf, dataset.columns["omega"] * uf, color="0.6", lw=3, alpha=0.6,
                label=f"{dataset.provenance.kind} curve (figure only, not fitted)")
    tc = curves[0][0].per_dataset[0].scene.area.contact_time
    for key, tx in (("omega_peak", st.get("t_peak")), ("omega_end", (tc, 0.0))):
        if key in st and tx is not None:
            ax.errorbar([tx[0] * tf], [st[key][0] * uf], xerr=[tx[1] * tf], yerr=[st[key][1] * uf], fmt="s",
                        color="black", ms=5, capsize=3, zorder=4, label="stated (± precision)" if key == "omega_peak" else None)
    tt = np.linspace(0.0, tc, 300)
    names = list(st)
    width = 0.8 / max(len(curves), 1)
    for i, (f, laws) in enumerate(curves):
        d = f.per_dataset[0]
        style = base._style(f.law, f.solver, i)
        tr = base.trajectory(d, f.law, tt)
        ax.plot(tr.t * tf, tr["omega"] * uf, label=base._label(f, rows, laws), zorder=3, **style)
        axr.bar(np.arange(len(names)) + (i - (len(curves) - 1) / 2) * width, d.residual / d.target.sigma, width,
                color=style.get("color"))
    axr.axhspan(-1, 1, color="0.85", zorder=0, label="±1 stated precision")
    axr.axhline(0, color="0.3", lw=0.8)
    axr.set_xticks(np.arange(len(names)), [STATED_LABELS.get(k, k) for k in names])
    axr.set_ylabel("(model − stated) / precision")
    ax.set_ylabel(f"spin ω [{uname}]")
    ax.set_xlabel(f"time [{tname}]")
    title = base.wrapped(f"{dataset.name}: fits to the stated numbers ({dataset.provenance.kind} data)", 6.7, 12)
    ax.set_title(title)
    ax.legend(fontsize=8, loc="best", framealpha=0.9)
    axr.legend(fontsize=8, loc="best")
    for a in (ax, axr):
        a.grid(alpha=0.3)
    base.margins(fig, top=base.EDGE + base.title_in(title, 12), bottom=base.XTICKS + base.EDGE,
                 hspace=base.XAXIS + base.GAP)
    return base._png(fig)
