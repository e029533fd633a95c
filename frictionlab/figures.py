"""Report figures as PNG bytes (matplotlib, Agg backend). Display units: rpm, deg, us/ms/s, N.

Each function takes results and returns PNG bytes; nothing here fits or ranks.
"""
from __future__ import annotations

import io

import numpy as np

from .display import NAMES, time_unit, unit

LAW_COLORS = {"coulomb": "#7f7f7f", "area-rate": "#d95f02", "wear": "#1b9e77", "couette": "#7570b3"}
EXTRA_COLORS = ["#e7298a", "#66a61e", "#e6ab02", "#a6761d", "#1f78b4"]
DPI = 110


def _plt():
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    return plt


def _png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI, bbox_inches="tight")
    _plt().close(fig)
    return buf.getvalue()


def _style(law: str, solver: str, i: int) -> dict:
    color = LAW_COLORS.get(law, EXTRA_COLORS[i % len(EXTRA_COLORS)])
    ls = "--" if solver == "series" else (":" if law == "couette" else "-")
    lw = 2.6 if law == "couette" else 1.7  # couette shares wear's form: dotted and wide so both show
    return {"color": color, "ls": ls, "lw": lw}


def _label(f, rows) -> str:
    r = next((r for r in rows if r.law == f.law and r.solver == f.solver), None)
    extra = f", ΔAIC {r.delta_aic:.1f}" if r is not None and r.rank is not None else ""
    return f"{f.law} [{f.solver}]{extra}"


def _x_axis(dataset, obs):
    """(x values [display], label, time factor or None): time if the dataset has it, else its first
    other column (rows of an impact-outcome set, e.g. incidence), else the row number."""
    if "t" in dataset.columns:
        t = dataset.t
        tname, tf = time_unit(float(t[-1]))
        return t * tf, f"time [{tname}]", tf
    for name, values in dataset.columns.items():
        if name != obs:
            uname, uf = unit(name)
            return values * uf, f"{NAMES.get(name, name)} [{uname}]", None
    return np.arange(len(dataset), dtype=float), "row", None


def fit_figure(dataset, fits, rows) -> bytes:
    """Data with every law's best fit (top) and residuals model - data with the ±1 sigma band (bottom)."""
    plt = _plt()
    ok = [f for f in fits if f.ok]
    target = ok[0].per_dataset[0].target if ok else None
    obs = target.observable if ok else dataset.observable
    uname, uf = unit(obs)
    x, xlabel, tf = _x_axis(dataset, obs)
    order = np.argsort(x, kind="stable")
    fig, (ax, axr) = plt.subplots(2, 1, figsize=(7.6, 6.2), sharex=True, gridspec_kw={"height_ratios": [3, 1.6]})
    y = target.y if ok else dataset.columns[obs]
    sigma = target.sigma if ok else np.full(x.shape, dataset.noise.get(obs, np.nan))
    kind = dataset.provenance.kind
    ax.errorbar(x, y * uf, yerr=sigma * uf, fmt="o", ms=3.2, color="black", ecolor="0.7", elinewidth=0.8,
                label=f"data ({kind})" + (f", {target.derivation}" if ok and target.derivation else ""), zorder=1)
    for i, f in enumerate(ok):
        d = f.per_dataset[0]
        style = _style(f.law, f.solver, i)
        tr = None
        if tf is not None:
            tr = d.trajectory(f.law, np.linspace(float(dataset.t[0]), float(dataset.t[-1]), 400))
        if tr is not None:
            ax.plot(tr.t * tf, tr[obs] * uf, label=_label(f, rows), zorder=3, **style)
        else:
            ax.plot(x[order], d.model[order] * uf, label=_label(f, rows), zorder=3, **style)
        axr.plot(x[order], d.residual[order] * uf, marker=".", ms=3, **style)
    axr.fill_between(x[order], -sigma[order] * uf, sigma[order] * uf, color="0.85", label="±1σ noise", zorder=0)
    axr.axhline(0, color="0.3", lw=0.8)
    ax.set_ylabel(f"{NAMES.get(obs, obs)} [{uname}]")
    axr.set_ylabel(f"model − data [{uname}]")
    axr.set_xlabel(xlabel)
    ax.set_title(f"{dataset.name}: fits of every law" + ("" if kind == "measured" else f"  ({kind} data)"))
    ax.legend(fontsize=8, loc="best", framealpha=0.9)
    axr.legend(fontsize=8, loc="best")
    for a in (ax, axr):
        a.grid(alpha=0.3)
    _residual_limits(axr, [f.per_dataset[0].residual * uf for f in ok], sigma * uf)
    return _png(fig)


def _residual_limits(ax, residuals, sigma):
    """Show all residuals, but never shrink below the noise band."""
    if not residuals:
        return
    top = max(float(np.max(np.abs(r))) for r in residuals)
    top = max(top, 1.5 * float(np.max(sigma)))
    ax.set_ylim(-1.08 * top, 1.08 * top)


def force_figure(dataset, fits) -> bytes:
    """The friction force history of every law's best fit."""
    plt = _plt()
    ok = [f for f in fits if f.ok and f.per_dataset[0].target.t is not None]
    t_end = float(dataset.t[-1])
    tname, tf = time_unit(t_end)
    fig, ax = plt.subplots(figsize=(7.6, 3.8))
    for i, f in enumerate(ok):
        tr = f.per_dataset[0].trajectory(f.law, np.linspace(0.0, t_end, 400))
        ax.plot(tr.t * tf, tr.force, label=f"{f.law} [{f.solver}]", **_style(f.law, f.solver, i))
    ax.axhline(0, color="0.3", lw=0.8)
    ax.set_xlabel(f"time [{tname}]")
    ax.set_ylabel("friction force F [N] (positive opposes slip)")
    ax.set_title(f"{dataset.name}: friction force of each best fit")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return _png(fig)


def ranking_figure(rows) -> bytes:
    """Heat map of delta-AIC, candidates x datasets, with ranks; grey where no fit."""
    plt = _plt()
    from matplotlib.colors import LogNorm

    datasets = list(dict.fromkeys(r.dataset for r in rows))
    row_of = lambda r: r.law + (" [series]" if r.solver == "series" else "")  # noqa: E731
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
    fig, ax = plt.subplots(figsize=(1.25 * len(datasets) + 3.2, 0.55 * len(cands) + 1.8))
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
    ax.set_title("Ranking per dataset: #rank and ΔAIC (solver exact unless named)")
    return _png(fig)


def derivation_figure(dataset, derived: dict, noisy: dict, sigma_theta: float, seed: int) -> bytes:
    """What each theta -> omega route does: on the theta column as given (left) and on the same
    column with simulated camera noise of the stated sigma (right)."""
    plt = _plt()
    t = dataset.t
    tname, tf = time_unit(float(t[-1]))
    du, df = unit("omega")
    au, af = unit("theta")
    fig, axes = plt.subplots(2, 2, figsize=(10.5, 6.6), sharex=True)
    colors = {"poly9": "#d95f02", "spline": "#1b9e77"}
    for col, (title, res) in enumerate((("theta column as given", derived),
                                        (f"with simulated noise σθ = {sigma_theta * af:.2g} {au} (seed {seed})",
                                         noisy))):
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
    fig.suptitle(f"{dataset.name}: spin derived from rotation angle (shaded: ±1σ each route passes on from θ noise)",
                 fontsize=11)
    fig.tight_layout()
    return _png(fig)


def equivalence_figure(dataset, fw_list, fa, decomps) -> bytes:
    """Friction force of the wear fits, the area-rate fit, and the paper's two-term decomposition
    of each wear fit with its projection onto mu N + mu eta' dA/dt."""
    plt = _plt()
    s = fa.per_dataset[0].scene
    t_end = float(dataset.t[-1])
    tname, tf = time_unit(t_end)
    t = np.linspace(0.0, t_end, 400)
    fig, axes = plt.subplots(1, max(1, len(fw_list)), figsize=(5.4 * max(1, len(fw_list)), 3.9), squeeze=False)
    Fa = fa.per_dataset[0].trajectory(fa.law, t).force
    for ax, fw, dec in zip(axes[0], fw_list, decomps):
        Fw = fw.per_dataset[0].trajectory(fw.law, t).force
        ax.plot(t * tf, Fw, color=LAW_COLORS["wear"], lw=2, ls="--" if fw.solver == "series" else "-",
                label=f"wear [{fw.solver}]")
        ax.plot(t * tf, Fa, color=LAW_COLORS["area-rate"], lw=2, label=f"area-rate [{fa.solver}]")
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
    fig.tight_layout()
    return _png(fig)


def discrimination_figure(dataset: str, results) -> bytes:
    """One panel per tested pair on ``dataset``: the distribution of T = chi2_A - chi2_B over the
    replicates of each law's fit, and the observed T."""
    plt = _plt()
    fig, axes = plt.subplots(1, len(results), figsize=(4.6 * len(results), 3.4), squeeze=False)
    for ax, e in zip(axes[0], results):
        both = np.concatenate([e.t_a, e.t_b, [e.t_obs]])
        span = float(np.ptp(both))
        if span <= 1e-4 * max(e.n_points, 1):
            ax.text(0.5, 0.5, f"one curve: T = 0 on the data\nand on all {e.t_a.size + e.t_b.size} replicates",
                    ha="center", va="center", transform=ax.transAxes)
        else:
            bins = np.linspace(both.min() - 0.02 * span, both.max() + 0.02 * span, 40)
            for t, law, solver in ((e.t_a, e.law_a, e.solver_a), (e.t_b, e.law_b, e.solver_b)):
                ax.hist(t, bins=bins, alpha=0.6, color=LAW_COLORS.get(law, "0.5"), label=f"data from {law} [{solver}]")
            ax.axvline(e.t_obs, color="k", lw=1.5, label="observed T")
            ax.legend(fontsize=7)
        ax.set_xlabel(f"T = χ²({e.law_a}) − χ²({e.law_b})")
        ax.set_ylabel("replicates")
        ax.set_title(f"{e.law_a} [{e.solver_a}] vs {e.law_b} [{e.solver_b}]: {e.verdict}", fontsize=9)
        ax.grid(alpha=0.3)
    fig.suptitle(f"{dataset}: the discrimination test (parametric bootstrap)", fontsize=11)
    fig.tight_layout()
    return _png(fig)


def is_png(data: bytes) -> bool:
    return data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 100
