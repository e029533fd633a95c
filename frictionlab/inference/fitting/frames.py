"""Results in the ecosystem's idiom: tidy pandas frames, lmfit Parameters and reports, notebook HTML.

Every number is SI, with its unit in a column of its own (``unit``, ``rss_unit``, ``rmse_unit``).
pandas and lmfit are imported only when one of these is called.
"""
from __future__ import annotations

import html
import math
import re

from ...io.dataset import COLUMN_SI

RANKING_COLUMNS = ("dataset", "law", "solver", "candidate", "rank", "status", "observable", "n_points", "n_params",
                   "rss", "rss_unit", "rmse", "rmse_unit", "redchi", "aic", "aicc", "bic", "delta_aic",
                   "akaike_weight", "reason", "plausibility_flags", "fits", "rank_effect")
PARAMETER_COLUMNS = ("dataset", "law", "solver", "parameter", "value", "stderr", "unit", "kind", "vary", "fixed_by",
                     "lower", "upper", "at_bound")


def _units(observable: str) -> tuple[str, str]:
    """(rss unit, rmse unit) of an observable, SI; '1' for a plain number."""
    u = COLUMN_SI.get(observable, "") or "1"
    return (f"({u})^2" if "/" in u else (u if u == "1" else f"{u}^2")), u


def ranking_frame(c):
    """Comparison.to_dataframe(): one row per dataset and candidate, then the group rows."""
    import pandas as pd

    obs = {d.name: d.observable for d in c.datasets}
    rows = []
    for r in list(c.ranking) + list(c.groups):
        o = obs.get(r.dataset, "")
        rss_u, rmse_u = _units(o) if o else ("", "")
        rows.append({"dataset": r.dataset, "law": r.law, "solver": r.solver, "candidate": r.candidate,
                     "rank": r.rank, "status": r.status, "observable": o, "n_points": r.n_points,
                     "n_params": r.n_params, "rss": r.rss, "rss_unit": rss_u, "rmse": r.rmse, "rmse_unit": rmse_u,
                     "redchi": r.redchi, "aic": r.aic, "aicc": r.aicc, "bic": r.bic, "delta_aic": r.delta_aic,
                     "akaike_weight": r.akaike_weight, "reason": r.reason, "plausibility_flags": "; ".join(r.flags),
                     "fits": r.fits, "rank_effect": _rank_effect(r)})
    df = pd.DataFrame(rows, columns=list(RANKING_COLUMNS))
    df["rank"] = df["rank"].astype("Int64")
    return df


def _rank_effect(r) -> str:
    """What a plausibility flag did to the candidate's place ('' without flags)."""
    if not r.flags:
        return ""
    return ("ranked after every unflagged candidate that fits (or is untested), whatever its AIC" if r.rank is not None else
            "flagged; not ranked")


def parameters_frame(fits):
    """One row per parameter of every successful fit (dataset joined with '+' for a global fit)."""
    import pandas as pd

    rows = []
    for f in fits:
        if not f.ok:
            continue
        for p in f.params.values():
            rows.append({"dataset": "+".join(f.datasets), "law": f.law, "solver": f.solver, "parameter": p.name,
                         "value": p.value, "stderr": p.stderr if p.stderr is not None else math.nan,
                         "unit": p.unit, "kind": p.kind, "vary": p.vary, "fixed_by": p.fixed_by,
                         "lower": p.lower, "upper": p.upper, "at_bound": p.at_bound})
    return pd.DataFrame(rows, columns=list(PARAMETER_COLUMNS))


def _lmfit_name(name: str) -> str:
    s = re.sub(r"\W", "_", name)
    return s if re.match(r"[A-Za-z_]", s) else f"p_{s}"


def lmfit_parameters(f):
    """FitResult.lmfit_params: lmfit.Parameters in SI with standard errors and correlations set."""
    import lmfit

    ps = lmfit.Parameters()
    names = {}
    for p in f.params.values():
        n = _lmfit_name(p.name)
        names[p.name] = n
        lo = p.lower if p.lower is not None and math.isfinite(p.lower) else -math.inf
        hi = p.upper if p.upper is not None and math.isfinite(p.upper) else math.inf
        if p.kind == "derived":
            lo, hi = -math.inf, math.inf
        ps.add(n, value=p.value, vary=p.vary and p.kind != "derived", min=min(lo, p.value), max=max(hi, p.value))
        ps[n].stderr = p.stderr
        ps[n].init_value = getattr(p, "initial", None)
    for (a, b), r in f.correlations.items():
        if a in names and b in names:
            ps[names[a]].correl = {**(ps[names[a]].correl or {}), names[b]: r}
            ps[names[b]].correl = {**(ps[names[b]].correl or {}), names[a]: r}
    return ps


def fit_report(f, **kwargs) -> str:
    """Our statistics, then lmfit's [[Variables]] and [[Correlations]] of the SI parameters."""
    import lmfit

    if not f.ok:
        return f"[[Fit]] {f.law} [{f.solver}] on {', '.join(f.datasets)}: {f.status}: {f.reason}"
    s = f.stats
    head = [f"[[Fit]] {f.law} [{f.solver}] on {', '.join(f.datasets)} (SI units)",
            f"    # data points      = {s.n_points}", f"    # variables        = {s.n_params} identifiable "
            f"({s.n_free} free)", f"    chi-square         = {s.chisqr:.6g}", f"    reduced chi-square = {s.redchi:.6g}",
            f"    Akaike info crit   = {s.aic:.6g}  ({aic_convention(f)})", f"    Bayesian info crit = {s.bic:.6g}",
            f"    function evals     = {f.nfev}"]
    head += [f"    warning: {w}" for w in f.identifiability.warnings]
    units = "\n".join(f"    {_lmfit_name(p.name)}: {p.unit or '(no unit)'}" + _bounds_text(p) for p in f.params.values())
    return (("\n".join(head) + "\n" + lmfit.fit_report(f.lmfit_params, **kwargs) + "\n[[Units and the law's bounds]]\n"
             + units + "\n    (lmfit's [lo:hi] shows inf where a bound lies beyond 1e4 typical scales of the "
             "parameter; the law's bound above still holds, and to_dataframe() shows it)"))


def _bounds_text(p) -> str:
    lo, hi = getattr(p, "lower", None), getattr(p, "upper", None)
    return "" if lo is None or hi is None else f", bounds [{lo:g}, {hi:g}]"


def aic_convention(f) -> str:
    """Which AIC this is, and lmfit's own (``minimizer_result.aic``: n ln(chi2/n) + 2 k, no constant) beside it."""
    s = f.stats
    ours = {"known": "-2 ln L + 2k with the stated sigma", "assumed": "-2 ln L + 2k, sigma profiled (k + 1)"}.get(
        s.likelihood, f"-2 ln L + 2k ({s.likelihood} likelihood)")
    mr = getattr(f, "minimizer_result", None)
    theirs = getattr(mr, "aic", None)
    return ours + ("" if theirs is None else f"; lmfit's minimizer_result.aic = {theirs:.6g} is n ln(chi2/n) + 2k, "
                   "without the constant: compare AICs of one convention only")


def _table(df, caption: str) -> str:
    return (f"<div><b>{html.escape(caption)}</b>" + df.to_html(index=False, na_rep="", float_format=lambda x: f"{x:.4g}")
            + "</div>")


def fit_html(f) -> str:
    """FitResult._repr_html_: one row of statistics with whether the fit passes its goodness-of-fit tests
    ("fits?"), then the parameters in their display units, rounded to their errors."""
    from ...core.display import param_cells
    from .plots import fits_text

    e = html.escape
    head = e(repr(f).strip("<>"))
    if not f.ok:
        return f"<p>{head}</p>"
    s = f.stats
    stats = ("<table><tr><th>law</th><th>solver</th><th>datasets</th><th>fits?</th><th>χ²</th><th>reduced χ²</th>"
             "<th>AIC</th><th>n</th><th>k</th></tr>"
             f"<tr><td>{e(f.law)}</td><td>{e(f.solver)}</td><td>{e(', '.join(f.datasets))}</td>"
             f"<td>{e(fits_text(f.goodness))}</td><td>{s.chisqr:.4g}</td><td>{s.redchi:.3g}</td><td>{s.aic:.4g}</td>"
             f"<td>{s.n_points}</td><td>{s.n_params}</td></tr></table>")
    rows = []
    for p in f.params.values():
        value, err, unit = param_cells(p.value, p.stderr, p.unit, p.shown)
        role = "fitted" if p.vary else (p.fixed_by or ("derived" if p.kind == "derived" else "held"))
        rows.append(f"<tr><td>{e(p.name)}</td><td>{e(value)}</td><td>{e(err)}</td><td>{e(unit or '-')}</td><td>{e(role)}</td></tr>")
    params = ("<table><tr><th>parameter</th><th>value</th><th>standard error</th><th>unit</th><th>role</th></tr>"
              + "".join(rows) + "</table>")
    flags = "".join(f"<p>implausible: {e(x)}</p>" for x in f.flags)
    return f"<div><p><b>{head}</b></p>{stats}{flags}<b>parameters</b>{params}</div>"


def comparison_html(c) -> str:
    """Comparison._repr_html_: the ranking table per dataset, with whether each candidate fits ("fits?")."""
    from .plots import fits_text

    df = ranking_frame(c)
    df = df[df["rank"].notna()].copy()
    goodness = {(r.dataset, r.law, r.solver): r.goodness for r in list(c.ranking) + list(c.groups)}
    df["fits?"] = [fits_text(goodness.get((d, law, s))) for d, law, s in zip(df["dataset"], df["law"], df["solver"])]
    cols = ["dataset", "candidate", "rank", "fits?", "status", "rmse", "rmse_unit", "redchi", "delta_aic",
            "akaike_weight"]
    return (f"<p>{html.escape(repr(c).strip('<>'))}</p>"
            + _table(df[cols], "ranking (SI units; a candidate is called best only if it fits; group rows at the end)"))
