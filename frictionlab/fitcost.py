"""What solver tolerance does to a fit: fitted values, error bars, fit time and the ranking.

``fit_tolerance_study(laws, dataset, methods, rtols)`` fits every law to one dataset with
``solver='ode:METHOD'`` at each tolerance, plus the closed form where it exists, and reports
per fit: parameters and lmfit standard errors, their shift from the reference fit in units of
the reference error bar, CPU time of the fit, AIC, the rank among the laws at that tolerance and
whether the ranking equals the reference ranking (laws within ranking.TIE_AIC share a place). The reference is the closed-form fit where
every law has one, else the tightest tolerance of the first method.

Hook: ``fitting.fit`` takes no tolerance argument yet; its predictions read ``predict.FIT_RTOL``
when they solve an ODE, so the study sets that module constant for the duration of each fit (in
this process only; not thread-safe). When ``fit`` grows an ``rtol`` argument, ``_fit`` is the one
place to change.
"""
from __future__ import annotations

import math
import time
from contextlib import contextmanager

from .errors import FrictionLabError

DEFAULT_RTOLS = (1e-3, 1e-5, 1e-7, 1e-10)


@contextmanager
def _fit_rtol(rtol):
    import importlib

    predict = importlib.import_module("frictionlab.predict")  # the package exports a function of that name
    old = predict.FIT_RTOL
    predict.FIT_RTOL = rtol
    try:
        yield
    finally:
        predict.FIT_RTOL = old


def _fit(law, dataset, solver, rtol):
    from .fitting import fit

    t0 = time.process_time()
    with _fit_rtol(rtol if rtol is not None else 1e-10):
        r = fit(law, dataset, solver=solver)
    return r, time.process_time() - t0


def _ranking(fits: dict) -> tuple[tuple[str, ...], dict]:
    """Laws grouped by AIC, best first; laws within ranking.TIE_AIC of each other share a group
    (wear and Couette are one model on some scenes). Also law -> rank (1 + laws clearly better)."""
    from .ranking import TIE_AIC

    ok = {law: f.stats.aic for law, f in fits.items() if f.ok}
    order = sorted(ok, key=ok.get)
    groups, rank = [], {}
    for law in order:
        if groups and ok[law] - ok[groups[-1][-1]] <= TIE_AIC:
            groups[-1].append(law)
        else:
            groups.append([law])
        rank[law] = 1 + sum(1 for o in order if ok[o] < ok[law] - TIE_AIC)
    return tuple(tuple(sorted(g)) for g in groups), rank


def fit_tolerance_study(laws, dataset, methods=("LSODA", "DOP853"), rtols=DEFAULT_RTOLS, progress=None) -> list[dict]:
    """Rows (one per law, solver, rtol, parameter): see the module docstring; SI units."""
    from .dataset import load_dataset
    from .predict import applicable_solvers

    ds = load_dataset(dataset)
    runs = []  # (solver, rtol)
    if all(applicable_solvers(law, ds.scene)["exact"] is None for law in laws):
        runs.append(("exact", None))
    runs += [(f"ode:{m}", r) for m in methods for r in sorted(rtols, reverse=True)]
    results = {}
    for solver, rtol in runs:
        for law in laws:
            if progress:
                progress(f"fit {law} to {ds.name} with {solver}" + (f" rtol={rtol:g}" if rtol else ""))
            try:
                results[(solver, rtol, law)] = _fit(law, ds, solver, rtol)
            except FrictionLabError as exc:
                results[(solver, rtol, law)] = (exc, math.nan)
    ref_run = runs[0] if runs[0][0] == "exact" else (runs[0][0], min(rtols))
    ref = {law: results[(*ref_run, law)][0] for law in laws}
    ref_rank = _ranking({k: v for k, v in ref.items() if not isinstance(v, Exception)})[0]
    rows = []
    for solver, rtol in runs:
        fits = {law: results[(solver, rtol, law)][0] for law in laws}
        good = {k: v for k, v in fits.items() if not isinstance(v, Exception)}
        rank, ranks = _ranking(good)
        for law in laws:
            f, secs = results[(solver, rtol, law)]
            base = {"dataset": ds.name, "law": law, "solver": solver, "rtol": rtol, "fit_time_s": secs,
                    "reference": f"{ref_run[0]}" + (f" rtol={ref_run[1]:g}" if ref_run[1] else ""),
                    "ranking": " > ".join(" = ".join(g) for g in rank), "ranking_as_reference": rank == ref_rank}
            if isinstance(f, Exception) or not f.ok:
                rows.append({**base, "status": str(f) if isinstance(f, Exception) else f"{f.status}: {f.reason}",
                             "parameter": "", "value": math.nan, "stderr": None, "shift_in_stderr": math.nan,
                             "aic": math.nan, "rank": None})
                continue
            r0 = ref.get(law)
            for name, p in f.params.items():
                if not p.vary:
                    continue
                shift = math.nan
                if r0 is not None and not isinstance(r0, Exception) and r0.ok and name in r0.params:
                    p0 = r0.params[name]
                    if p0.stderr:
                        shift = (p.value - p0.value) / p0.stderr
                rows.append({**base, "status": "ok", "parameter": name, "value": p.value, "stderr": p.stderr,
                             "shift_in_stderr": shift, "aic": f.stats.aic,
                             "rank": ranks.get(law)})
    return rows


def markdown(rows) -> str:
    """A Markdown table of ``fit_tolerance_study`` rows."""
    if not rows:
        return ""
    lines = [f"Reference: {rows[0]['reference']}. 'shift' is (value - reference value) / reference standard error; "
             "fit time is CPU seconds.", "",
             "| law | solver | rtol | parameter | value | stderr | shift | fit time [s] | AIC | rank | ranking | as reference |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        def f(x, spec):
            return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, spec)

        lines.append(f"| {r['law']} | {r['solver']} | {f(r['rtol'], '.0e')} | {r['parameter'] or r['status']} | "
                     f"{f(r['value'], '.6g')} | {f(r['stderr'], '.3g')} | {f(r['shift_in_stderr'], '.2g')} | "
                     f"{f(r['fit_time_s'], '.3g')} | {f(r['aic'], '.6g')} | {r['rank'] or '-'} | {r['ranking']} | "
                     f"{'yes' if r['ranking_as_reference'] else 'NO'} |")
    return "\n".join(lines)
