"""The paper's equivalence claim: force histories and the discrimination test's distributions."""
from __future__ import annotations

import numpy as np

from ...core.display import time_unit
from . import base


def equivalence_figure(dataset, fw_list, fa, decomps) -> bytes:
    """The paper's two-term decomposition of each wear fit (a panel per fit in ``fw_list``, each with its
    decomposition in ``decomps``) with its projection onto mu N + mu eta' dA/dt, over the friction force
    of that wear fit and the area-rate fit ``fa``. Forces in N, time in the display unit."""
    s = fa.per_dataset[0].scene
    t_end = float(dataset.t[-1])
    tname, tf = time_unit(t_end)
    t = np.linspace(0.0, t_end, 400)
    fig, axes = base.subplots("equivalence", 1, max(1, len(fw_list)), figsize=(5.4 * max(1, len(fw_list)), 4.7))
    Fa = fa.per_dataset[0].trajectory(fa.law, t).force
    A, dA = s.area(t)
    A = np.where(t <= s.area.contact_time, A, 0.0)
    N = s.normal(t, A)  # the decomposition's terms, the same for every panel
    for ax, fw, dec in zip(axes[0], fw_list, decomps):
        Fw = fw.per_dataset[0].trajectory(fw.law, t).force
        ax.plot(t * tf, Fw, color=base.LAW_COLORS["wear"], lw=2, ls="--" if fw.solver == "series" else "-",
                label=f"wear [{fw.solver}]")
        ax.plot(t * tf, Fa, color=base.LAW_COLORS["area-rate"], lw=2, label=f"area-rate [{fa.solver}]")
        ax.plot(t * tf, dec.c_area * A, color="0.45", lw=1, ls="-.", label="λu0(1−b)A")
        ax.plot(t * tf, dec.c_area_rate * A * dA, color="0.45", lw=1, ls=":", label="(λu0b/(φA0)) A dA/dt")
        ax.plot(t * tf, dec.mu * (N + dec.eta_prime * dA), color="#e7298a", lw=1.2,
                label=f"implied μN+μη'dA/dt (μ = {dec.mu:.3g}, η' = {dec.eta_prime:.3g} N s/m²)")
        ax.axhline(0, color="0.3", lw=0.8)
        ax.set_xlabel(f"time [{tname}]")
        ax.set_ylabel("friction force [N]")
        ax.set_title(f"wear [{fw.solver}] vs area-rate", fontsize=10)
        ax.grid(alpha=0.3)
        below = base.legend_below(ax, fontsize=7, ncol=2)
    title = base.wrapped(f"{dataset.name}: is λAu equivalent to μN + μη' dA/dt?", fig.get_figwidth() - 0.3, 11)
    base.margins(fig, top=base.suptitle(fig, title, 11) + base.title_in(axes[0, 0].get_title(), 10),
                 bottom=below + base.EDGE)
    return base._png(fig)


def one_curve(e) -> bool:
    """Whether the pair's T is zero (to 1e-4 per data point) on the data and on every replicate: one curve."""
    both = np.concatenate([e.t_a, e.t_b, [e.t_obs]])
    return float(np.ptp(both)) <= 1e-4 * max(e.n_points, 1)


def discrimination_figure(dataset: str, results) -> bytes:
    """One panel per tested pair on ``dataset`` whose laws differ: the distribution of T = chi2_A - chi2_B
    over the replicates of each law's fit, and the observed T. Pairs that are one curve (T = 0 throughout)
    get no panel, only a line under the title."""
    from matplotlib.ticker import MaxNLocator

    drawn = [e for e in results if not one_curve(e)]
    same = [e for e in results if one_curve(e)]
    fig, axes = base.subplots("discrimination", 1, max(1, len(drawn)),
                              figsize=(4.6 * max(1, len(drawn)), 3.4))
    for ax, e in zip(axes[0], drawn):
        both = np.concatenate([e.t_a, e.t_b, [e.t_obs]])
        span = float(np.ptp(both))
        bins = np.linspace(both.min() - 0.02 * span, both.max() + 0.02 * span, 40)
        for t, law, solver in ((e.t_a, e.law_a, e.solver_a), (e.t_b, e.law_b, e.solver_b)):
            ax.hist(t, bins=bins, alpha=0.6, color=base.LAW_COLORS.get(law, "0.5"), histtype="stepfilled",
                    label=f"data from {law} [{solver}]")
        ax.axvline(e.t_obs, color="k", lw=1.5, label="observed T")
        ax.legend(fontsize=7, loc="best")
        ax.xaxis.set_major_locator(MaxNLocator(nbins=5))
        ax.ticklabel_format(axis="x", style="sci", scilimits=(-3, 4))  # text offset: mathtext is off (core.display.pyplot)
        ax.set_xlabel(f"T = χ²({e.law_a}) − χ²({e.law_b})")
        ax.set_ylabel("replicates")
        ax.set_title(base.wrapped(f"{e.law_a} [{e.solver_a}] vs {e.law_b} [{e.solver_b}]: {e.verdict}", 4.4, 9),
                     fontsize=9)
        ax.grid(alpha=0.3)
    if not drawn:
        axes[0, 0].set_axis_off()
    title = f"{dataset}: the discrimination test (parametric bootstrap)"
    if same:
        title += "\n" + "; ".join(f"{e.law_a} [{e.solver_a}] = {e.law_b} [{e.solver_b}]" for e in same) + \
            ": one curve (T = 0 on the data and on every replicate), not drawn"
    pt = 11 if len(drawn) > 1 else 9.5
    title = "\n".join(base.wrapped(line, fig.get_figwidth() - 0.3, pt) for line in title.split("\n"))
    top = base.suptitle(fig, title, pt) + max((base.title_in(ax.get_title(), 9) for ax in axes[0]), default=0.0)
    base.margins(fig, top=top, bottom=base.XAXIS + base.EDGE)
    return base._png(fig)
