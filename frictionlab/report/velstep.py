"""The first screen's velocity steps: for each measured velocity-step dataset its fitted rate-and-state
parameters (a, b, a - b, Dc, k, mu0 and the trend, with intervals, in laboratory units) beside its figure (data,
fit, residuals), and what the fit says about the sign of a - b, the bounds and the noise. Called once by
``first_screen.build``; reads only the fits' ``velstep`` reports."""
from __future__ import annotations

from .figures.velstep import velstep_figure

#: Columns of the table: (StepReport quantity, header).
COLUMNS = (("a", "a"), ("b", "b"), ("a-b", "a − b"), ("Dc", "Dc [µm]"), ("k", "k [1/µm]"))


def measured_steps(c, datasets=None) -> list:
    """(dataset, its velocity-step fits best-ranked first) for every measured dataset (of ``datasets``; default
    the comparison's fitted ones) fitted as velocity steps."""
    out = []
    for d in c.fitted_datasets if datasets is None else datasets:
        fits = [f for f in c.fits_on(d.name) if f.ok and getattr(f, "velstep", None) is not None
                and len(f.datasets) == 1]
        if d.provenance.kind != "measured" or not fits:
            continue
        rank = {r.law: r.rank or 99 for r in c.ranking if r.dataset == d.name}
        out.append((d, sorted(fits, key=lambda f: (rank.get(f.law, 99), f.law))))
    return out


def window(d) -> str:
    """Where an imported dataset's window starts and why ('starts at ..., at steady state: ...'), from its
    provenance; '' for a dataset that does not say."""
    method = d.provenance.method or ""
    return method.split("; the window ", 1)[1] if "; the window " in method else ""


def cell(q) -> str:
    """'0.00892 ± 0.00026' of a velstep_result.Quantity (its 95% interval is in the figure)."""
    if q is None:
        return "—"
    if q.stderr is None:
        return f"{q.value:.3g} ({q.missing})"
    return f"{q.value:.{q.digits - 1}g} ± {q.stderr:.2g}"


def first_screen(sec, c, datasets=None) -> list[str]:
    """Add the measured velocity steps (of ``datasets``) to the first screen ``sec``; the names of those shown."""
    steps = measured_steps(c, datasets)
    if not steps:
        return []
    rows = []
    for d, fits in steps:
        for f in fits:
            q = f.velstep.rows[0].quantities
            law = f.law.replace("rate-state-", "")
            row = f.velstep.rows[0]
            noise = ", ".join(f"{m} at {lab}" for lab, m in row.noise) or ", ".join(
                f"AR(1) φ = {p:.2f} at {lab}" for lab, p in row.phi) or "independent"
            white = ("white" if f.goodness.noise_ok else "not white") if f.goodness.noise_ok is not None else "—"
            rows.append([f"**{d.name}**", law] + [cell(q.get(key)) for key, _ in COLUMNS]
                        + [noise, white, f.goodness.short])
    sec.p("**Measured velocity steps** (value ± standard error; Dc in µm, k in 1/µm; the 95% intervals, μ0, the "
          "trend and the noise in each figure):")
    sec.table(["dataset", "rate-and-state law"] + [h for _, h in COLUMNS]
              + ["noise model", "whitened residuals", "does the law fit"], rows)
    for d, fits in steps:
        best = fits[0]
        said = [s for f in fits[:1] for s in (f.velstep.sign + f.velstep.bounds + f.velstep.noise + f.velstep.missing)]
        said += [f"The parameters come from the dataset's window, which {w}" for w in [window(d)] if w]
        sec.fig(f"velstep-{d.name}.png", f"{d.name} (measured): the data with the {best.law} fit, the step close up, "
                "the residuals (fit − data) and the fitted parameters.", lambda f=best: velstep_figure(f),
                side=" ".join(f"{s}." for s in said), key=("velstep", id(best)))  # the index's and its group's
    return [d.name for d, _ in steps]
