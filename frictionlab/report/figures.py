"""Report figures as PNG bytes (matplotlib, Agg backend). Display units: rpm, deg, us/ms/s, N.

Each function takes results and returns PNG bytes; nothing here fits or ranks.
"""
from __future__ import annotations

import io

import numpy as np

from ..core.display import NAMES, time_unit, unit
from ..core.errors import FrictionLabError

LAW_COLORS = {"coulomb": "#7f7f7f", "area-rate": "#d95f02", "wear": "#1b9e77", "couette": "#7570b3"}
EXTRA_COLORS = ["#e7298a", "#66a61e", "#e6ab02", "#a6761d", "#1f78b4"]
DPI = 110
#: Two fits are one curve when they differ by at most this fraction of the noise at every data point.
SAME_CURVE = 1e-3


def _plt():
    from ..core.display import pyplot

    return pyplot()


def _png(fig) -> bytes:
    """The figure as PNG bytes at DPI. A layout engine (constrained layout) is run here, at the
    saving DPI, and then switched off: savefig would otherwise draw the whole figure once more
    (without rendering) just to run it. The same bytes as a plain savefig (tests/test_report.py)."""
    buf = io.BytesIO()
    engine = fig.get_layout_engine()
    if engine is not None:
        fig.set_dpi(DPI)
        engine.execute(fig)
        fig.set_layout_engine(None)
    fig.savefig(buf, format="png", dpi=DPI)
    _plt().close(fig)
    return buf.getvalue()


def _style(law: str, solver: str, i: int) -> dict:
    color = LAW_COLORS.get(law, EXTRA_COLORS[i % len(EXTRA_COLORS)])
    ls = "--" if solver == "series" else "-"
    return {"color": color, "ls": ls, "lw": 1.8}


def _label(f, rows, laws=None) -> str:
    r = next((r for r in rows if r.law == f.law and r.solver == f.solver), None)
    extra = f", ΔAIC {r.delta_aic:.1f}" if r is not None and r.rank is not None else ""
    return f"{' = '.join(laws or [f.law])} [{f.solver}]{extra}"


def same_curve(a, b) -> bool:
    """Whether two fits of one dataset with one solver predict the same curve at every data point (within
    SAME_CURVE sigma): laws of one functional form, or a law whose extra term has no effect there."""
    if a.solver != b.solver or len(a.per_dataset) != len(b.per_dataset):
        return False
    for da, db in zip(a.per_dataset, b.per_dataset):
        if da.model.shape != db.model.shape or not np.all(np.abs(da.model - db.model) <= SAME_CURVE * da.target.sigma):
            return False
    return True


def distinct_curves(fits) -> list[tuple[object, list[str]]]:
    """(representative fit, the laws whose fits are that same curve, sorted) for successful fits, in order."""
    out: list[tuple[object, list[str]]] = []
    for f in fits:
        if not f.ok:
            continue
        for rep, laws in out:
            if same_curve(rep, f):
                laws.append(f.law)
                break
        else:
            out.append((f, [f.law]))
    return [(f, sorted(laws)) for f, laws in out]


def fit_figure(dataset, fits, rows) -> bytes:
    """Data with every distinct best fit (top) and residuals model - data with the ±1 sigma band (bottom).
    Laws whose fits are the same curve (one functional form) are one entry; a dataset without time
    (rows are impacts) goes to ``outcome_figure``."""
    if "t" not in dataset.columns:
        return outcome_figure(dataset, fits, rows)
    curves = distinct_curves(fits)
    if curves and curves[0][0].per_dataset[0].target.observable == "stated":
        return stated_figure(dataset, curves, rows)
    plt = _plt()
    target = curves[0][0].per_dataset[0].target if curves else None
    obs = target.observable if curves else dataset.observable
    uname, uf = unit(obs)
    t = dataset.t
    tname, tf = time_unit(float(t[-1]))
    fig, (ax, axr) = plt.subplots(2, 1, figsize=(7.6, 6.0), sharex=True, gridspec_kw={"height_ratios": [3, 1.6]},
                                  layout="constrained")
    y = target.y if curves else dataset.columns[obs]
    sigma = target.sigma if curves else np.full(t.shape, dataset.noise.get(obs, np.nan))
    kind = dataset.provenance.kind
    ax.errorbar(t * tf, y * uf, yerr=sigma * uf, fmt="o", ms=3.2, color="black", ecolor="0.7", elinewidth=0.8,
                label=f"data ({kind})" + (f", {target.derivation}" if curves and target.derivation else ""), zorder=1)
    tt = np.linspace(float(t[0]), float(t[-1]), 300)
    for i, (f, laws) in enumerate(curves):
        d = f.per_dataset[0]
        style = _style(f.law, f.solver, i)
        try:
            tr = d.trajectory(f.law, tt)
            ax.plot(tr.t * tf, tr[obs] * uf, label=_label(f, rows, laws), zorder=3, **style)
        except FrictionLabError:  # a stiff law whose dense curve exceeds the solver's budget: the fitted points
            ax.plot(t * tf, d.model * uf, label=_label(f, rows, laws), zorder=3, **style)
        axr.plot(t * tf, d.residual * uf, marker=".", ms=3, **style)
    axr.fill_between(t * tf, -sigma * uf, sigma * uf, color="0.85", label="±1σ noise", zorder=0)
    axr.axhline(0, color="0.3", lw=0.8)
    ax.set_ylabel(f"{NAMES.get(obs, obs)} [{uname}]")
    axr.set_ylabel(f"model − data [{uname}]")
    axr.set_xlabel(f"time [{tname}]")
    ax.set_title(f"{dataset.name}: fits of every law" + ("" if kind == "measured" else f"  ({kind} data)"))
    ax.legend(fontsize=8, loc="best", framealpha=0.9)
    axr.legend(fontsize=8, loc="best")
    for a in (ax, axr):
        a.grid(alpha=0.3)
    _residual_limits(axr, [f.per_dataset[0].residual * uf for f, _ in curves], sigma * uf)
    return _png(fig)


STATED_LABELS = {"omega_peak": "peak ω", "t_peak": "its time", "omega_end": "ω at t_c", "theta_max": "largest θ"}


def stated_figure(dataset, curves, rows) -> bytes:
    """A reconstruction fitted on its stated numbers: the noise-free spin curve (grey, drawn for the figure
    only) with the stated peak and end-of-contact spin as crosses of their stated precision and each
    distinct fit's spin (top); each stated number's miss (model − stated) / precision (bottom)."""
    plt = _plt()
    t = dataset.t
    tname, tf = time_unit(float(t[-1]))
    uname, uf = unit("omega")
    st = dataset.stated
    fig, (ax, axr) = plt.subplots(2, 1, figsize=(7.6, 6.0), gridspec_kw={"height_ratios": [3, 1.6]},
                                  layout="constrained")
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
        style = _style(f.law, f.solver, i)
        tr = d.trajectory(f.law, tt)
        ax.plot(tr.t * tf, tr["omega"] * uf, label=_label(f, rows, laws), zorder=3, **style)
        axr.bar(np.arange(len(names)) + (i - (len(curves) - 1) / 2) * width, d.residual / d.target.sigma, width,
                color=style.get("color"))
    axr.axhspan(-1, 1, color="0.85", zorder=0, label="±1 stated precision")
    axr.axhline(0, color="0.3", lw=0.8)
    axr.set_xticks(np.arange(len(names)), [STATED_LABELS.get(k, k) for k in names])
    axr.set_ylabel("(model − stated) / precision")
    ax.set_ylabel(f"spin ω [{uname}]")
    ax.set_xlabel(f"time [{tname}]")
    ax.set_title(f"{dataset.name}: fits to the stated numbers ({dataset.provenance.kind} data)")
    ax.legend(fontsize=8, loc="best", framealpha=0.9)
    axr.legend(fontsize=8, loc="best")
    for a in (ax, axr):
        a.grid(alpha=0.3)
    return _png(fig)


def column_unit(dataset, name: str) -> tuple[str, float]:
    """(unit, factor from SI) of column ``name`` as the dataset's file gives it ('' for a plain number)."""
    from ..core.units import unit_factor
    from ..io.dataset import COLUMN_SI

    u = dataset.units.get(name, "")
    si = COLUMN_SI.get(name, "")
    try:
        return u, 1.0 / unit_factor(u, si, name)
    except Exception:  # an odd unit string: show SI
        return si, 1.0


def outcome_figure(dataset, fits, rows) -> bytes:
    """Impact-outcome rows: each distinct fit's prediction against the observation (left) and the
    observation against impact angle (right; one line per group of the other inputs, e.g. speed,
    never joining different groups), in the dataset's own units."""
    plt = _plt()
    curves = distinct_curves(fits)
    obs = dataset.observable
    uname, uf = column_unit(dataset, obs)
    ylab = f"{obs.replace('_', ' ')}" + (f" [{uname}]" if uname else "")
    y = dataset.columns[obs] * uf
    sigma = dataset.noise.get(obs, 0.0) * uf
    angle = next((c for c in dataset.columns if c != obs and c in ("incidence", "angle")), None)
    others = [c for c in dataset.columns if c not in (obs, angle) and c in ("speed", "spin")
              and len(np.unique(dataset.columns[c])) > 1]
    fig, (axp, axa) = plt.subplots(1, 2, figsize=(11.0, 4.6), layout="constrained",
                                   gridspec_kw={"width_ratios": [1, 1.35]})
    lo, hi = float(np.min(y)), float(np.max(y))
    for i, (f, laws) in enumerate(curves):
        st = _style(f.law, f.solver, i)
        axp.plot(y, f.per_dataset[0].model * uf, "o", ms=4, color=st["color"], alpha=0.85,
                 label=_label(f, rows, laws))
        lo, hi = min(lo, float(np.min(f.per_dataset[0].model * uf))), max(hi, float(np.max(f.per_dataset[0].model * uf)))
    pad = 0.05 * (hi - lo or 1.0)
    axp.plot([lo - pad, hi + pad], [lo - pad, hi + pad], color="0.3", lw=0.9, label="predicted = observed")
    axp.set_xlabel(f"observed {ylab}")
    axp.set_ylabel(f"predicted {ylab}")
    axp.set_title("predicted against observed", fontsize=10)
    axp.legend(fontsize=7.5)
    if angle is not None:
        au, af = column_unit(dataset, angle)
        x = dataset.columns[angle] * af
        keys = [tuple(dataset.columns[c][k] for c in others) for k in range(len(dataset))]
        groups = list(dict.fromkeys(keys))
        markers = "osD^v<>"
        for gi, key in enumerate(groups):
            idx = np.array([k for k in range(len(dataset)) if keys[k] == key])
            idx = idx[np.argsort(x[idx], kind="stable")]
            glabel = ", ".join(f"{c} {key[j] * column_unit(dataset, c)[1]:.3g} {column_unit(dataset, c)[0]}"
                               for j, c in enumerate(others)) or "data"
            axa.errorbar(x[idx], y[idx], yerr=sigma, fmt=markers[gi % len(markers)], ms=4, color="black",
                         ecolor="0.7", elinewidth=0.7, label=f"data: {glabel}", zorder=1)
            for i, (f, laws) in enumerate(curves):
                st = _style(f.law, f.solver, i)
                axa.plot(x[idx], f.per_dataset[0].model[idx] * uf, color=st["color"], ls=st["ls"], lw=1.4,
                         label=_label(f, rows, laws) if gi == 0 else None, zorder=2)
        axa.set_xlabel(f"{angle} [{au}]")
        axa.set_ylabel(ylab)
        axa.set_title(f"against {angle}" + (f", one line per {' and '.join(others)}" if others else ""), fontsize=10)
        axa.legend(fontsize=7, ncol=2)
    else:
        axa.set_visible(False)
    for a in (axp, axa):
        a.grid(alpha=0.3)
    kind = dataset.provenance.kind
    fig.suptitle(f"{dataset.name}: fits of every law" + ("" if kind == "measured" else f"  ({kind} data)"),
                 fontsize=11)
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
    curves = [(f, laws) for f, laws in distinct_curves(fits) if f.per_dataset[0].target.t is not None]
    t_end = float(dataset.t[-1])
    tname, tf = time_unit(t_end)
    fig, ax = plt.subplots(figsize=(7.6, 3.8), layout="constrained")
    drawn = 0
    for i, (f, laws) in enumerate(curves):
        try:
            tr = f.per_dataset[0].trajectory(f.law, np.linspace(0.0, t_end, 300))
        except FrictionLabError:  # a stiff law whose dense curve exceeds the solver's budget: left out
            continue
        ax.plot(tr.t * tf, tr.force, label=f"{' = '.join(laws)} [{f.solver}]", **_style(f.law, f.solver, i))
        drawn += 1
    ax.axhline(0, color="0.3", lw=0.8)
    ax.set_xlabel(f"time [{tname}]")
    ax.set_ylabel("friction force F [N] (positive opposes slip)")
    ax.set_title(f"{dataset.name}: friction force of each best fit")
    ax.grid(alpha=0.3)
    if drawn:
        ax.legend(fontsize=8)
    else:
        ax.text(0.5, 0.5, "no fit's force history could be drawn\n(each exceeded the solver's budget)",
                transform=ax.transAxes, ha="center", va="center", color="0.3")
    return _png(fig)


def ranking_figure(rows, alias: dict | None = None) -> bytes:
    """Heat map of delta-AIC, candidates x datasets, with ranks; grey where no fit. ``alias`` maps a law
    to the label it shares with laws of the same curve everywhere ("couette = wear"): one row for them."""
    plt = _plt()
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
    fig, axes = plt.subplots(2, 2, figsize=(10.5, 6.6), sharex=True, layout="constrained")
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
    return _png(fig)


def equivalence_figure(dataset, fw_list, fa, decomps) -> bytes:
    """Friction force of the wear fits, the area-rate fit, and the paper's two-term decomposition
    of each wear fit with its projection onto mu N + mu eta' dA/dt."""
    plt = _plt()
    s = fa.per_dataset[0].scene
    t_end = float(dataset.t[-1])
    tname, tf = time_unit(t_end)
    t = np.linspace(0.0, t_end, 400)
    fig, axes = plt.subplots(1, max(1, len(fw_list)), figsize=(5.4 * max(1, len(fw_list)), 3.9), squeeze=False, layout="constrained")
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
    return _png(fig)


def finding_figure(findings) -> bytes:
    """Per finding (report.first_screen.SeriesFinding), one column: the data's spin with the series and the
    exact fit of the same law (top), the slip u(t) of each (bottom), the series' zero crossing marked."""
    plt = _plt()
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
    return _png(fig)


def discrimination_figure(dataset: str, results) -> bytes:
    """One panel per tested pair on ``dataset``: the distribution of T = chi2_A - chi2_B over the
    replicates of each law's fit, and the observed T."""
    plt = _plt()
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
                ax.hist(t, bins=bins, alpha=0.6, color=LAW_COLORS.get(law, "0.5"), histtype="stepfilled",
                        label=f"data from {law} [{solver}]")
            ax.axvline(e.t_obs, color="k", lw=1.5, label="observed T")
            ax.legend(fontsize=7)
        ax.set_xlabel(f"T = χ²({e.law_a}) − χ²({e.law_b})")
        ax.set_ylabel("replicates")
        ax.set_title(f"{e.law_a} [{e.solver_a}] vs {e.law_b} [{e.solver_b}]: {e.verdict}", fontsize=9)
        ax.grid(alpha=0.3)
    fig.suptitle(f"{dataset}: the discrimination test (parametric bootstrap)", fontsize=11)
    return _png(fig)


def is_png(data: bytes) -> bool:
    return data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 100
