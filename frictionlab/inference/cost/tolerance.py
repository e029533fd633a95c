"""What solver tolerance does to a fit: fitted values, error bars, fit time and the ranking.

``fit_tolerance_study(laws, dataset, methods, rtols)`` fits every law to one dataset with
``solver='ode:METHOD'`` at each tolerance (``fitting.fit(..., rtol=...)``), plus the closed form
where it exists, and reports per fit: parameters and lmfit standard errors, their shift from the
reference fit in units of the reference error bar, CPU time of the fit, AIC, the rank among the
laws at that tolerance and whether the ranking equals the reference ranking (laws within
ranking.TIE_AIC share a place). The reference is the closed-form fit where every law has one,
else the tightest tolerance of the first method, or fits the caller already has (``reference``,
e.g. a comparison's at the default tolerance). Fits may run on an executor: the tolerance is an
argument of each fit, never shared state.

``tolerance_check(fits, rtols)`` is the cheap version for the comparison report: on the first
dataset where some law needs the ODE, only those laws are refitted at ``rtols``, against the
comparison's own fits; ``frictionlab bench`` runs the full study.
"""
from __future__ import annotations

import math

from ...core.errors import FrictionLabError

DEFAULT_RTOLS = (1e-3, 1e-5, 1e-7, 1e-10)


def _fit(law, dataset, solver, rtol, options=None):
    """(FitResult or the one-line error, CPU seconds of the fit); a third-party law's fit within its
    budget from outside its code (``inference.fitting.guard``)."""
    from ..fitting.guard import within_budget

    timeout = (options or {}).get("timeout")
    return within_budget(_fit_here, (law,), timeout, law, dataset, solver, rtol, options,
                         over=lambda why: (FrictionLabError(f"{law}: {why}"), math.nan))


def _fit_here(law, dataset, solver, rtol, options=None):
    from ..fitting.fit import fit

    try:
        r = fit(law, dataset, solver=solver, rtol=rtol, **(options or {}))
    except FrictionLabError as exc:
        return exc, math.nan
    return r, r.cpu_time


def _ranking(fits: dict) -> tuple[tuple[str, ...], dict]:
    """Laws grouped by AIC, best first; laws within ranking.TIE_AIC of each other share a group
    (wear and Couette are one model on some scenes). Also law -> rank (1 + laws clearly better)."""
    from ..verdicts.ranking import TIE_AIC

    ok = {law: f.stats.aic for law, f in fits.items() if not isinstance(f, Exception) and f.ok}
    order = sorted(ok, key=ok.get)
    groups, rank = [], {}
    for law in order:
        if groups and ok[law] - ok[groups[-1][-1]] <= TIE_AIC:
            groups[-1].append(law)
        else:
            groups.append([law])
        rank[law] = 1 + sum(1 for o in order if ok[o] < ok[law] - TIE_AIC)
    from ...physics.registry import get_law

    simplest = lambda law: (len(get_law(law).params), law)  # noqa: E731  'wear = couette', as the ranking spells it
    return tuple(tuple(sorted(g, key=simplest)) for g in groups), rank


def _run_fits(todo, ds, executor, progress, options) -> dict:
    """(solver, rtol, law) -> (FitResult or error, CPU seconds), fitted here or on ``executor``."""
    label = lambda s, r, law: f"fit {law} to {ds.name} with {s}" + (f" rtol={r:g}" if r else "")  # noqa: E731
    tell = progress or (lambda text, done: None)  # progress(label, done): False as a fit starts, True as it ends
    if executor is None:
        out = {}
        for key in todo:
            tell(label(*key), False)
            out[key] = _fit(key[2], ds, key[0], key[1], options)
            tell(label(*key), True)
        return out
    futures = {key: executor.submit(_fit, key[2], ds, key[0], key[1], options) for key in todo}
    out = {}
    for key, fut in futures.items():
        if not fut.done():
            tell(label(*key), False)
        out[key] = fut.result()
        tell(label(*key), True)
    return out


def fit_tolerance_study(laws, dataset, methods=("LSODA", "DOP853"), rtols=DEFAULT_RTOLS, progress=None, *,
                        reference: dict | None = None, others: dict | None = None, executor=None,
                        fit_options: dict | None = None) -> list[dict]:
    """Rows (one per law, solver, rtol, parameter): see the module docstring; SI units.

    reference: law -> FitResult made at the default tolerance (predict.FIT_RTOL); these are the
    reference and are not refitted (their rows carry that rtol). others: law -> FitResult of laws
    that need no ODE on this dataset: they join every ranking, unchanged. executor: anything with
    ``submit(fn, *args)`` (e.g. a process pool) to run the fits on. fit_options: further keyword
    arguments of every ``fitting.fit`` (e.g. the ``free`` scene quantities of the reference fits).
    progress(label, done): told as each refit starts (done False) and ends (done True).
    """
    from ...io.dataset import load_dataset
    from ...solve.choice import applicable_solvers
    from ..fitting.predict import FIT_RTOL

    ds = load_dataset(dataset)
    runs = []  # (solver, rtol); solver None: the given reference fits
    if reference:
        runs.append((None, FIT_RTOL))
    elif all(applicable_solvers(law, ds.scene)["exact"] is None for law in laws):
        runs.append(("exact", None))
    runs += [(f"ode:{m}", r) for m in methods for r in sorted(rtols, reverse=True)]
    results = {(None, FIT_RTOL, law): (reference[law], reference[law].cpu_time) for law in laws} if reference else {}
    results.update(_run_fits([(s, r, law) for s, r in runs if s is not None for law in laws], ds, executor, progress,
                              fit_options))
    if reference:
        ref_run, ref_label = runs[0], f"the given fits at rtol {FIT_RTOL:g}"
    else:
        ref_run = runs[0] if runs[0][0] == "exact" else (runs[0][0], min(rtols))
        ref_label = f"{ref_run[0]}" + (f" rtol={ref_run[1]:g}" if ref_run[1] else "")
    others = dict(others or {})
    ref = {law: results[(*ref_run, law)][0] for law in laws}
    ref_rank = _ranking({**others, **ref})[0]
    rows = []
    for solver, rtol in runs:
        fits = {law: results[(solver, rtol, law)][0] for law in laws}
        rank, ranks = _ranking({**others, **fits})
        for law in laws:
            f, secs = results[(solver, rtol, law)]
            base = {"dataset": ds.name, "law": law, "solver": solver or f.solver, "rtol": rtol, "fit_time_s": secs,
                    "reference": ref_label, "ranking": " > ".join(" = ".join(g) for g in rank),
                    "ranking_as_reference": rank == ref_rank}
            if isinstance(f, Exception) or not f.ok:
                rows.append({**base, "status": str(f) if isinstance(f, Exception) else f"{f.status}: {f.reason}",
                             "parameter": "", "value": math.nan, "stderr": None, "unit": "",
                             "shift_in_stderr": math.nan, "aic": math.nan, "rank": None})
                continue
            r0 = ref.get(law)
            for name in f.determined:
                p = f.params[name]
                shift = math.nan
                if r0 is not None and not isinstance(r0, Exception) and r0.ok and name in r0.params:
                    p0 = r0.params[name]
                    if p0.stderr:
                        shift = (p.value - p0.value) / p0.stderr
                rows.append({**base, "status": "ok", "parameter": name, "value": p.value, "stderr": p.stderr,
                             "unit": p.unit, "shown": p.shown, "shift_in_stderr": shift, "aic": f.stats.aic, "rank": ranks.get(law)})
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


def tolerance_check(fits, rtols=(1e-3, 1e-6), executor=None, n_datasets: int = 1, progress=None,
                    fit_options: dict | None = None) -> list[dict]:
    """``fit_tolerance_study`` rows for the first ``n_datasets`` datasets (in the order of ``fits``,
    a comparison's single-dataset FitResults) on which a law is solved by 'ode'. Only those laws
    are refitted, at each of ``rtols`` with the same ODE method; their fits in ``fits`` are the
    reference, and the laws solved otherwise there join the ranking unchanged. The paper's series
    is an approximation of a law, not a law, and is left out of this ranking."""
    from ...solve.solvers import parse_solver
    from ..verdicts.ranking import family

    by_ds: dict = {}
    for f in fits:
        if len(f.datasets) == 1 and f.ok and family(f.solver) == "full":
            by_ds.setdefault(f.datasets[0], {}).setdefault(f.law, f)
    rows = []
    for laws in by_ds.values():
        ode = {law: f for law, f in laws.items() if f.solver.startswith("ode")}
        if not ode:
            continue
        method = parse_solver(next(iter(ode.values())).solver)[1]
        ode = {law: f for law, f in ode.items() if parse_solver(f.solver)[1] == method}
        others = {law: f for law, f in laws.items() if law not in ode}
        ds = next(iter(ode.values())).per_dataset[0].target.dataset
        rows += fit_tolerance_study(list(ode), ds, (method,), rtols, progress, reference=ode, others=others,
                                    executor=executor, fit_options=fit_options)
        n_datasets -= 1
        if n_datasets <= 0:
            break
    return rows
