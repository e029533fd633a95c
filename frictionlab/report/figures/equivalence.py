"""The paper's equivalence claim: force histories and the discrimination test's distributions."""
from __future__ import annotations

import numpy as np

from ...core.display import time_unit
from . import base


def equivalence_figure(dataset, fw_list, fa, decomps) -> bytes:
    """Friction force of the wear fits, the area-rate fit, and the paper's two-term decomposition
    of each wear fit with its projection onto mu N + mu eta' dA/dt."""
    plt = base._plt()
    s = fa.per_dataset[0].scene
    t_end = float(dataset.t[-1])
    tname, tf = time_unit(t_end)
    t = np.linspace(0.0, t_end, 400)
    fig, axes = plt.subplots(1, max(1, len(fw_list)), figsize=(5.4 * max(1, len(fw_list)), 3.9), squeeze=False, layout="constrained")
    Fa = fa.per_dataset[0].trajectory(fa.law, t).force
    for ax, fw, dec in zip(axes[0], fw_list, decomps):
        Fw = fw.per_dataset[0].trajectory(fw.law, t).force
        ax.plot(t * tf, Fw, color=base.LAW_COLORS["wear"], lw=2, ls="--" if fw.solver == "series" else "-",
                label=f"wear [{fw.solver}]")
        ax.plot(t * tf, Fa, color=base.LAW_COLORS["area-rate"], lw=2, label=f"area-rate [{fa.solver}]")
        if dec is not None:
            A, dA = s.area(t)
            A = np.where(t <= s.area.contact_time, A, 0.0)
            N = s.normal(t, A)
            ax.plot(t * tf, dec.c_area * A, color="0.45", lw=1, ls="-.", label="λu0(1−b)A")
            ax.plot(t * tf, dec.c_area_rate * A * dA, color="0.45", lw=1, ls=":", label="(λu0b/(φA0)) A dA/dt")
            ax.plot(t * tf, dec.mu * (N + dec.eta_prime * dA), color="#e7298a", lw=1.2,
                    label=f"implied μN+μη'dA/dt (μ={dec.mu:.3g}, η'={dec.eta_prime:.3g})")
        ax.axhline(0, color="0.3", lw=0.8)
        ax.set_xlabel(f"time [{tname}]")
        ax.set_ylabel("friction force [N]")
        ax.set_title(f"wear [{fw.solver}] vs area-rate", fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(f"{dataset.name}: is λAu equivalent to μN + μη' dA/dt?", fontsize=11)
    return base._png(fig)


def discrimination_figure(dataset: str, results) -> bytes:
    """One panel per tested pair on ``dataset``: the distribution of T = chi2_A - chi2_B over the
    replicates of each law's fit, and the observed T."""
    plt = base._plt()
    fig, axes = plt.subplots(1, len(results), figsize=(4.6 * len(results), 3.4), squeeze=False, layout="constrained")
    for ax, e in zip(axes[0], results):
        both = np.concatenate([e.t_a, e.t_b, [e.t_obs]])
        span = float(np.ptp(both))
        if span <= 1e-4 * max(e.n_points, 1):
            ax.text(0.5, 0.5, f"one curve: T = 0 on the data\nand on all {e.t_a.size + e.t_b.size} replicates",
                    ha="center", va="center", transform=ax.transAxes)
        else:
            bins = np.linspace(both.min() - 0.02 * span, both.max() + 0.02 * span, 40)
            for t, law, solver in ((e.t_a, e.law_a, e.solver_a), (e.t_b, e.law_b, e.solver_b)):
                ax.hist(t, bins=bins, alpha=0.6, color=base.LAW_COLORS.get(law, "0.5"), histtype="stepfilled",
                        label=f"data from {law} [{solver}]")
            ax.axvline(e.t_obs, color="k", lw=1.5, label="observed T")
            ax.legend(fontsize=7)
        ax.set_xlabel(f"T = χ²({e.law_a}) − χ²({e.law_b})")
        ax.set_ylabel("replicates")
        ax.set_title(f"{e.law_a} [{e.solver_a}] vs {e.law_b} [{e.solver_b}]: {e.verdict}", fontsize=9)
        ax.grid(alpha=0.3)
    fig.suptitle(f"{dataset}: the discrimination test (parametric bootstrap)", fontsize=11)
    return base._png(fig)
