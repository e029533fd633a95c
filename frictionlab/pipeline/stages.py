"""The named stages of ``compare``, in order: fit, rank, equivalence, transfer, tolerance, accuracy, bootstrap,
answer. Each reads the comparison so far and returns the fields of ``Comparison`` it fills.

- fit: every planned (law, dataset, solver) fitted (``inference.fitting.fit.fit``) -> ``fits``
- rank: per dataset and per group (``inference.verdicts.ranking``) -> ``ranking``, ``groups``
- equivalence: the discrimination test per pair and dataset (``inference.equivalence.discrimination``) -> ``equivalence``
- transfer: one parameter set across a group's conditions (``inference.equivalence.transfer``) -> ``transfer``
- tolerance: the ODE laws of one dataset refitted at other tolerances (``inference.cost.tolerance``) -> ``tolerance``
- accuracy: what accuracy costs, each solver's error and time against the most accurate one per law and
  dataset (``inference.cost.accuracy``; by default where cheap, in full with the tolerance check) -> ``accuracy``
- bootstrap: parametric replicates, intervals and first-place shares (``inference.resampling.bootstrap``) ->
  ``bootstrap``, ``bootstrap_skipped``
- answer: one verdict row per dataset group, the first screen (``inference.verdicts.group_verdicts``) -> ``answers``
"""
from __future__ import annotations

import functools

from ..core.errors import FrictionLabError
from ..inference.cost import accuracy as _accuracy
from ..inference.equivalence import family as _equivalence
from ..inference.equivalence import transfer as _transfer
from ..inference.verdicts.answers import group_of
from ..inference.cost.accuracy import SolverCost, solver_costs, study_fits
from ..inference.resampling.ranking_bootstrap import bootstrap_fits
from ..inference.equivalence.discrimination import EquivalenceResult, analyze_equivalence
from ..inference.cost.tolerance import tolerance_check
from ..inference.fitting.fit import FitResult
from ..inference.verdicts.ranking import family, rank_fits, rank_groups
from ..inference.verdicts.group_verdicts import make_answers, not_fitted_answers
from ..inference.fitting.guard import within_budget  # a plugin's time budget kept from outside its code, every stage
from .budget import fit_within_budget as fit_one
from .planning import pair_index, slow_pair
from .runner import Run, Stage


def fit(c, run: Run) -> dict:
    timeout = run.settings.fit_timeout
    results = run.map(functools.partial(_fit_task, timeout=timeout), run.plan.tasks,
                      lambda t: f"{t[0]} [{t[2]}] on {t[1].name}")
    fits = sorted(list(c.fits) + results, key=fit_order(c))
    if not run.part:  # a cluster's per-dataset task: checked once its parts are merged (pipeline.perdataset)
        check_some_fit(fits)
    return {"fits": tuple(fits)}


def fit_order(c):
    """The sort key of the comparison's fits: dataset, law, the paper's series last (a stable sort)."""
    order = {d.name: i for i, d in enumerate(c.datasets)}
    return lambda f: (order[f.datasets[0]], c.laws.index(f.law), family(f.solver) == "series")


def check_some_fit(fits) -> None:
    """The one-line error when no candidate could be fitted at all."""
    if all(f.status == "skipped" for f in fits):
        reasons = list(dict.fromkeys(f.reason for f in fits))
        raise FrictionLabError("compare: no fit could be made: " + "; ".join(reasons[:3])
                               + (f" (and {len(reasons) - 3} more reasons)" if len(reasons) > 3 else ""))


def _fit_task(args, timeout=None) -> FitResult:
    law, dataset, solver, free = args
    try:
        return fit_one(law, dataset, solver=solver, free=free, timeout=timeout)
    except FrictionLabError as exc:  # e.g. a freed scene quantity this scene does not have
        return FitResult(law=law, solver=solver, datasets=(dataset.name,), status="skipped", reason=str(exc))


def rank(c, run: Run) -> dict:
    run.tally().total = 1
    ranking = rank_fits(c.fits)
    kinds = {d.name: d.kind for d in c.datasets}
    groups = rank_groups(ranking, kinds, named={d.name: group_of(d) for d in c.datasets})
    run.step(f"{len(ranking)} fits ranked in {len(groups)} groups")
    return {"ranking": tuple(ranking), "groups": tuple(groups)}


def equivalence(c, run: Run) -> dict:
    s = run.settings
    lookup = {(f.datasets[0], f.law, f.solver): f for f in c.fits}
    tasks, slow = [], []
    for d, (la, sa), (lb, sb) in run.eq_pairs:
        fa, fb = lookup[(d, la, sa)], lookup[(d, lb, sb)]
        why = slow_pair(fa, fb, s.replicates) if not s.bootstrap_all else ""
        if why:
            slow.append(EquivalenceResult(dataset=d, law_a=la, law_b=lb, solver_a=sa, solver_b=sb,
                                          status="skipped", reason=why, replicates=s.replicates, seed=s.seed))
        else:
            tasks.append((fa, fb, s.replicates, s.seed, s.fit_timeout, s.margin))
    if slow:  # counted first: the count then ends with the last test run
        run.tally().total += len(slow)
        run.step(f"{len(slow)} pairs skipped (slow; --bootstrap-all tests them)", advance=len(slow))
    results = run.map(_equivalence_task, tasks, lambda t: f"equivalence on {t[0].datasets[0]}: {t[0].law} "
                                                          f"[{t[0].solver}] vs {t[1].law} [{t[1].solver}]")
    results = tuple(sorted(results + slow, key=equivalence_order(c, s.pairs)))
    if not run.part:  # a cluster's per-dataset task: adjusted once the parts are merged (pipeline.perdataset)
        results = family_adjusted(c, results, s)
    return {"equivalence": results}


def family_adjusted(c, results, settings) -> tuple:
    """The tests' p-values adjusted as one family (``equivalence_groups.adjust_family``)."""
    return _equivalence.adjust_family(results, settings.family, {d.name: group_of(d) for d in c.datasets})


def equivalence_order(c, pairs):
    """The sort key of the equivalence results: dataset, pair, the paper's series last (a stable sort)."""
    order = {d.name: i for i, d in enumerate(c.datasets)}
    return lambda e: (order[e.dataset], pair_index(pairs, e), "series" in (e.solver_a, e.solver_b))


def _equivalence_task(args) -> EquivalenceResult:
    fa, fb, replicates, seed, timeout, margin = args
    over = lambda why: EquivalenceResult(  # noqa: E731
        dataset=fa.datasets[0], law_a=fa.law, law_b=fb.law, solver_a=fa.solver, solver_b=fb.solver,
        replicates=replicates, seed=seed, status="failed", reason=f"a refit {why}")
    return within_budget(analyze_equivalence, (fa.law, fb.law), timeout, fa, fb, replicates, seed, None, None,
                         timeout, margin, over=over)


def transfer(c, run: Run) -> dict:
    by_group = _transfer.candidates_by_group(c.fits, c.datasets)
    tasks = [(g, cand, fs) for g, cands in by_group.items() for cand, fs in cands.items()]
    free = dict(run.settings.free)
    parts = run.map(_transfer_task, [(fs, free, run.settings.fit_timeout, g, cand) for g, cand, fs in tasks],
                    lambda t: f"one parameter set for {t[4]} over group {t[3]}")
    results = [_transfer.assemble(g, cands, {cand: p for (gg, cand, _), p in zip(tasks, parts) if gg == g})
               for g, cands in by_group.items()]
    return {"transfer": tuple(results + _transfer.skipped(c.datasets, fits=c.fits))}


def _transfer_task(args):
    fits, free, timeout = args[:3]
    return within_budget(_transfer.transfer_candidate, (fits[0].law,), timeout, fits, free, timeout,
                         over=functools.partial(_transfer.failed_candidate, fits))


def tolerance(c, run: Run) -> dict:
    rtols = tuple(run.settings.tolerance)
    refits = len(rtols) * _ode_laws(c.fits)  # the laws solved by 'ode' on the first such dataset
    run.tally().total = max(refits, 1)
    run.step(f"refitting at rtol {', '.join(f'{r:g}' for r in rtols)}" if refits else
             "nothing to refit: no law is solved by 'ode' here", advance=not refits)
    rows = tolerance_check(c.fits, rtols, run.pool, fit_options=run.settings.fit_options() or None,
                           progress=lambda label, done: run.step(label if done else f"running {label}", advance=done))
    return {"tolerance": tuple(rows)}


def accuracy(c, run: Run) -> dict:
    """In this process: a few predictions per law and dataset (1.3 CPU s on the built-in data) cost less than
    sending the fits to the workers. On a cluster it runs in each dataset's task, beside its fits
    (``pipeline.perdataset``)."""
    fits = study_fits(c.fits)
    full = bool(run.settings.tolerance)  # --tolerance asks for the whole study, the costly rows too
    run.tally().total = max(len(fits), 1)
    rows = []
    for f in fits:
        rows += _accuracy_task(f, full=full, timeout=run.settings.fit_timeout)
        run.step(f"what accuracy costs: {f.law} on {f.datasets[0]}")
    return {"accuracy": tuple(rows)}


def _accuracy_task(f, full=False, timeout=None):
    over = lambda why: (SolverCost(dataset=f.datasets[0], law=f.law, solver="all", status="failed",  # noqa: E731
                                   reason=why),)
    return within_budget(solver_costs, (f.law,), timeout, f, full, over=over)


def bootstrap(c, run: Run) -> dict:
    s = run.settings
    seen: dict = {}  # dataset -> resamples done; the stage counts resamples over every dataset

    def told(name, k, n):
        run.tally().total = max(run.tally().total, s.bootstrap * len({f.datasets[0] for f in c.fits}))
        run.step(f"on {name}: {k}/{n} resamples", advance=k - seen.get(name, 0))
        seen[name] = k

    boots, skipped = bootstrap_fits(
        c.fits, s.bootstrap, s.seed, run.pool, s.bootstrap_all, s.free or None, timeout=s.fit_timeout,
        progress=told)
    return {"bootstrap": tuple(boots), "bootstrap_skipped": skipped}


def answer(c, run: Run) -> dict:
    run.tally().total = 1
    fitted = [d for d in c.datasets if d.name not in c.skipped_datasets]
    answers = make_answers(fitted, c.fits, c.ranking, c.groups)
    # the verdict layer's rows; the equivalence and transfer fields are filled by their producers
    answers = _transfer.fill_answers(_equivalence.fill_answers(answers, c.equivalence), c.transfer)
    answers = _accuracy.fill_answers(answers, c.accuracy)
    not_applicable = {k: v for k, v in c.skipped_datasets.items() if k in run.plan.no_law}
    answers = answers + not_fitted_answers(c.datasets, not_applicable, fitted)
    run.step(f"{len(answers)} verdict row{'s' * (len(answers) != 1)}")
    return {"answers": answers}


def _ode_laws(fits) -> int:
    """How many laws the tolerance check refits: those solved by 'ode' on the first such dataset."""
    for name in dict.fromkeys(f.datasets[0] for f in fits):
        n = len({f.law for f in fits if f.datasets == (name,) and f.ok and f.solver.startswith("ode")})
        if n:
            return n
    return 0


#: The pipeline, in order; ``compare(stages=[...])`` runs the ones named, ``run_stages`` continues a comparison.
STAGES = (
    Stage("fit", fit, lambda run: True),
    Stage("rank", rank, lambda run: True),
    Stage("equivalence", equivalence, lambda run: run.settings.equivalence and bool(run.eq_pairs)),
    Stage("transfer", transfer, lambda run: run.settings.transfer),
    Stage("tolerance", tolerance, lambda run: bool(run.settings.tolerance), beside=True),
    Stage("accuracy", accuracy, lambda run: run.settings.accuracy),
    Stage("bootstrap", bootstrap, lambda run: run.settings.bootstrap > 0),
    Stage("answer", answer, lambda run: True),
)
