"""Compare laws on datasets: every (law, dataset, solver) fitted, ranked, and the equivalence tested.

``compare(laws=None, datasets=None, solvers=None)`` with no arguments compares every registered
law on every built-in dataset. Solvers: by default each law is solved 'exact' where a closed
form exists for the dataset's scene, else 'ode', and additionally 'series' where the paper's
expansion applies; an explicit list fits each solver that applies (the others are recorded as
skipped with the reason). Contact-area datasets are supporting series and are not fitted; a
dataset kind without a predictor is skipped with that reason. Nothing here raises for a fit
that fails: it becomes a row with status 'failed' and its reason.

The equivalence stage runs the discrimination test (``equivalence.analyze_equivalence``) on the
pairs of ``equivalence.PAIRS`` per dataset (the paper's pair also with the wear law's series), and
the transfer stage (``transfer``) predicts across the members of each dataset group and fits one
parameter set to the group. Optionally (``bootstrap=N``) every candidate is refitted to N case resamples of its dataset
(``bootstrap.bootstrap_fits``: parameter intervals and how often each candidate ranks first), and
(``tolerance=rtols``) the laws that need the ODE on one dataset are refitted at looser
tolerances (``fitcost.tolerance_check``). Every stage runs on one process pool when jobs > 1.
"""
from __future__ import annotations

import functools
import os
import platform
import re
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool

import attrs
import numpy as np

from ..core.errors import FrictionLabError, ParameterError
from ..core.workers import process_pool
from ..inference import equivalence_groups as _equivalence
from ..inference import transfer as _transfer
from ..inference.answers import group_of
from ..inference.bootstrap import bootstrap_fits
from ..inference.equivalence import (
    MIN_REPLICATES,
    PAIRS,
    REPLICATES,
    EquivalenceResult,
    analyze_equivalence,
)
from ..inference.fitcost import tolerance_check
from ..inference.fitting import (
    PREDICTORS,
    FitResult,
    applicable_solvers,
    auto_solver,
    fit,
)
from ..inference.ranking import RankRow, family, rank_fits, rank_groups
from ..inference.transfer import (
    TransferResult,
    assemble,
    candidates_by_group,
    transfer_candidate,
)
from ..inference.verdicts import make_answers, not_fitted_answers
from ..io.dataset import Dataset, builtin_names, load_dataset
from ..physics.registry import available_laws, get_law

Progress = Callable[[int, int, str], None]


@attrs.frozen(eq=False)
class Comparison:
    """Everything a report needs: fits, rankings, equivalence results, and what was left out."""

    laws: tuple[str, ...]
    datasets: tuple[Dataset, ...]  # every dataset asked for, fitted or not
    fits: tuple[FitResult, ...]
    ranking: tuple[RankRow, ...]  # per dataset
    groups: tuple[RankRow, ...]  # ALL, ALL[kind] and each dataset group of two or more
    equivalence: tuple[EquivalenceResult, ...]  # discrimination tests (law A vs law B per dataset)
    skipped_datasets: dict  # name -> reason
    wall_time: float
    versions: dict
    settings: dict
    bootstrap: tuple = ()  # bootstrap.RankingBootstrap per bootstrapped dataset
    bootstrap_skipped: dict = attrs.field(factory=dict)  # dataset -> why it was not bootstrapped
    tolerance: tuple[dict, ...] = ()  # fitcost.tolerance_check rows
    timings: dict = attrs.field(factory=dict)  # stage -> wall-clock seconds
    transfer: tuple[TransferResult, ...] = ()  # per dataset group with two or more members
    answers: tuple = ()  # answers.Answer per dataset group: the report's first screen (filled by the verdict layer)

    def fit_for(self, dataset: str, law: str, solver: str | None = None) -> FitResult | None:
        for f in self.fits:
            if f.datasets == (dataset,) and f.law == law and (solver is None or f.solver == solver):
                return f
        return None

    def fits_on(self, dataset: str) -> list[FitResult]:
        return [f for f in self.fits if f.datasets == (dataset,)]

    def dataset(self, name: str) -> Dataset:
        return next(d for d in self.datasets if d.name == name)

    @property
    def fitted_datasets(self) -> list[Dataset]:
        return [d for d in self.datasets if d.name not in self.skipped_datasets]

    def to_dataframe(self):
        """The ranking as a tidy pandas DataFrame: one row per dataset and candidate (law, solver), with
        the observable and the units of rss and rmse; group rows (ALL, ALL[kind]) after them."""
        from ..inference.frames import ranking_frame

        return ranking_frame(self)

    def parameters_dataframe(self):
        """Every fitted parameter as a tidy pandas DataFrame: dataset, law, solver, parameter, value,
        stderr, unit, kind, vary, fixed_by, lower, upper."""
        from ..inference.frames import parameters_frame

        return parameters_frame(self.fits)

    def __repr__(self) -> str:
        ok = sum(f.ok for f in self.fits)
        best = "; ".join(f"{d.name}: " + " = ".join(r.candidate for r in self.ranking if r.dataset == d.name
                                                    and r.rank == 1) for d in self.fitted_datasets[:3])
        more = f"; ... {len(self.fitted_datasets) - 3} more" if len(self.fitted_datasets) > 3 else ""
        return (f"<Comparison of {len(self.laws)} laws on {len(self.fitted_datasets)} datasets: {ok} fits; "
                f"lowest AIC: {best}{more}>")

    def _repr_html_(self) -> str:
        from ..inference.frames import comparison_html

        return comparison_html(self)


def versions() -> dict:
    import lmfit
    import matplotlib
    import scipy

    from ..core import __version__

    return {"frictionlab": __version__, "python": platform.python_version(), "numpy": np.__version__,
            "scipy": scipy.__version__, "lmfit": lmfit.__version__, "matplotlib": matplotlib.__version__,
            "platform": platform.platform(), "cpus": os.cpu_count()}


def candidates(law, dataset: Dataset, solvers: Sequence[str] | None) -> list[tuple[str, str | None]]:
    """(solver, reason it does not apply or None) for ``law`` on ``dataset``."""
    law = get_law(law)
    ok = applicable_solvers(law, dataset.scene)
    if solvers is None:
        solver = auto_solver(law, dataset.scene)
        if solver == "ode" and dataset.kind == "impact-outcome" and ok["ode"] is None:
            # every evaluation integrates every impact of the set: minutes per fit for a stateful law
            return [("ode", f"law '{law.name}' has no closed form on impact outcomes, and fitting it with the ODE "
                            "simulates every impact at each evaluation (minutes per fit): name the solver "
                            "(--solver ode) to fit it")]
        out = [(solver, ok["ode"])]
        if ok["series"] is None:
            out.append(("series", None))
        return out
    out = []
    for s in solvers:
        if s == "auto":
            out.append((auto_solver(law, dataset.scene), ok["ode"]))
        else:
            out.append((s, ok.get(s.partition(":")[0])))
    return list(dict.fromkeys(out))  # 'auto' and the solver it picks name one candidate


def no_law_applies(dataset: Dataset, skipped, solvers=None) -> str:
    """The one reason a dataset is left out when no law compared can be fitted to it: the laws grouped by
    why not, and the registered laws that could be (skipped: (law, solver, reason) per candidate)."""
    by_reason: dict[str, list[str]] = {}
    for law, _, why in skipped:
        why = re.sub(rf"^law '{re.escape(law)}' (on an? [\w-]+: )?", "", why)
        why = re.sub(r", which \w+ cannot supply:.*$", ", which it does not have", why)
        by_reason.setdefault(why, [])
        if law not in by_reason[why]:
            by_reason[why].append(law)
    compared = set(law for law, _, _ in skipped)
    able = [n for n in available_laws() if n not in compared
            and any(why is None for _, why in candidates(n, dataset, solvers))]
    which = ("the one law compared does not apply" if len(compared) == 1
             else f"none of the {len(compared)} laws compared applies")
    text = (f"{which} to this {dataset.kind} set ("
            + "; ".join(f"{', '.join(laws)}: {why}" for why, laws in by_reason.items()) + ")")
    return text + (f"; registered laws that apply: {', '.join(able)} (--laws {','.join(able)})" if able else "")


def _fit_task(args, timeout=None) -> FitResult:
    law, dataset, solver, free = args
    try:
        return fit(law, dataset, solver=solver, free=free, timeout=timeout)
    except FrictionLabError as exc:  # e.g. a freed scene quantity this scene does not have
        return FitResult(law=law, solver=solver, datasets=(dataset.name,), status="skipped", reason=str(exc))


def _equivalence_task(args) -> EquivalenceResult:
    fa, fb, replicates, seed, timeout = args
    return analyze_equivalence(fa, fb, replicates=replicates, seed=seed, timeout=timeout)


def _transfer_task(args):
    fits, free, timeout = args
    return transfer_candidate(fits, free, timeout)


def _run(tasks, fn, pool, progress, done, total, label):
    """Run fn over tasks, on the pool if there is one; results in task order."""
    results = [None] * len(tasks)
    if pool is not None and len(tasks) > 1:
        futures = {pool.submit(fn, t): i for i, t in enumerate(tasks)}
        for fut in as_completed(futures):
            i = futures[fut]
            try:
                results[i] = fut.result()
            except BrokenProcessPool:  # a worker was killed, or a plugin ended its process (os._exit)
                raise FrictionLabError(f"compare: a worker process died while running {label(tasks[i])} "
                                       "(killed, out of memory, or a law plugin that ends its process)") from None
            done += 1
            if progress:
                progress(done, total, label(tasks[i]))
        return results, done
    for i, t in enumerate(tasks):
        results[i] = fn(t)
        done += 1
        if progress:
            progress(done, total, label(t))
    return results, done


#: The laws ``compare`` fits by default: the four of the mission (the seed paper's question). Other
#: registered laws (stribeck, lugre, dahl, rate-and-state, installed plugins) join when named or with "all".
DEFAULT_LAWS = ("coulomb", "area-rate", "wear", "couette")


def select_laws(laws: Sequence[str] | None) -> tuple[str, ...]:
    """Law names to compare: None -> DEFAULT_LAWS; "all" (alone or in the list) -> every registered law."""
    if laws is None:
        names = DEFAULT_LAWS
    elif isinstance(laws, str):
        names = (laws,)
    else:
        names = tuple(laws)
    if "all" in names:
        names = tuple(available_laws()) + tuple(n for n in names if n != "all")
    return tuple(dict.fromkeys(get_law(n).name for n in names))


def compare(laws: Sequence[str] | None = None, datasets: Sequence | None = None, solvers: Sequence[str] | None = None,
            *, free: dict | None = None, equivalence: bool = True, jobs: int = 1,
            progress: Progress | None = None, bootstrap: int = 0, seed: int = 0, bootstrap_all: bool = False,
            tolerance: Sequence[float] = (), fit_timeout: float | None = None, replicates: int = REPLICATES,
            pairs: Sequence = PAIRS, transfer: bool = True) -> Comparison:
    """Fit every law to every dataset with every applicable solver, rank, and test the equivalence.

    laws: registered names, None for DEFAULT_LAWS, or "all" for every registered law; datasets: built-in names, TOML paths or Datasets
    (default every built-in); solvers: None for the default choice, or a list of 'exact',
    'series', 'ode[:METHOD]', 'auto'; free: scene quantities fitted per dataset, name -> (lower,
    upper) in SI (see fitting.SCENE_QUANTITIES); jobs: worker processes; progress(done, total, label).
    bootstrap: case resamples per dataset (0: none), drawn from ``seed``; datasets where a law
    needs the ODE, or without a time series, are bootstrapped only with bootstrap_all. tolerance: looser ODE tolerances at
    which the ODE laws of one dataset are refitted (empty: no tolerance check). fit_timeout: time
    budget of each fit in seconds (None: none), the refits of the equivalence test, bootstrap, transfer
    and tolerance check included; a fit past it is a failed row saying so (a refit, a failed replicate). replicates: R per
    law of the equivalence test's parametric bootstrap (seeded by ``seed``); pairs: (law A, law B)
    to test (default equivalence.PAIRS); pairs where a law needs the ODE solver, or without a time
    series, are tested only with bootstrap_all. transfer: run the transfer stage.
    """
    started = time.perf_counter()
    from ..solve.solvers import parse_solver

    for s in solvers or ():
        if s != "auto":
            parse_solver(s)  # an unknown solver is an input error, before any work
    for name, v in (("bootstrap", bootstrap), ("seed", seed), ("replicates", replicates)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 0:
            raise ParameterError(f"compare: {name} must be a non-negative integer, got {v!r}")
    if fit_timeout is not None and (isinstance(fit_timeout, bool) or not isinstance(fit_timeout, (int, float))
                                    or not 0 < fit_timeout < float("inf")):
        raise ParameterError(f"compare: fit_timeout must be a positive number of seconds, got {fit_timeout!r}")
    for r in tolerance:
        if isinstance(r, bool) or not isinstance(r, (int, float)) or not 0 < r < 1:
            raise ParameterError(f"compare: every tolerance must be a number in (0, 1), got {r!r}")
    law_names = select_laws(laws)
    dss = _unique_datasets(load_dataset(d) for d in (datasets if datasets is not None else builtin_names()))
    if not dss:
        raise FrictionLabError("compare: no datasets to compare")
    skipped_ds, plan, fits, no_law = {}, [], [], set()
    for ds in dss:
        if ds.kind == "contact-area":
            skipped_ds[ds.name] = "contact-area series: supporting data (the area model of a scene), not fitted"
            continue
        if ds.kind not in PREDICTORS:
            skipped_ds[ds.name] = f"no predictor for dataset kind '{ds.kind}' yet"
            continue
        mine = [(law, solver, why) for law in law_names for solver, why in candidates(law, ds, solvers)]
        if mine and all(why for _, _, why in mine):  # nothing to fit: one reason for the dataset, not a row per law
            skipped_ds[ds.name] = no_law_applies(ds, mine, solvers)
            no_law.add(ds.name)
            continue
        for law, solver, why in mine:
            if why:
                fits.append(FitResult(law=law, solver=solver, datasets=(ds.name,), status="skipped", reason=why))
            else:
                plan.append((law, ds, solver, dict(free or {})))
    if len(skipped_ds) == len(dss):
        raise FrictionLabError("compare: none of the datasets can be fitted: "
                               + "; ".join(f"{k}: {v}" for k, v in skipped_ds.items()))
    # slow fits first (ode, then sets without a time series, which simulate every row), so that workers finish together
    plan.sort(key=lambda x: (not x[2].startswith("ode"), x[1].scene is None or "t" in x[1].columns))
    if equivalence and replicates < MIN_REPLICATES:
        raise ParameterError(f"compare: replicates must be at least {MIN_REPLICATES}, got {replicates}")
    eq_pairs = _equivalence_pairs(law_names, plan, pairs) if equivalence else []
    n_boot = len({f.datasets[0] for f in fits} | {t[1].name for t in plan}) if bootstrap else 0
    total = len(plan) + len(eq_pairs) + n_boot + (1 if tolerance else 0)
    label = lambda t: f"{t[0]} [{t[2]}] on {t[1].name}"  # noqa: E731
    timings, boots, boot_skipped, tol_rows = {}, [], {}, []
    order = {d.name: i for i, d in enumerate(dss)}
    if jobs > 1:
        import lmfit  # noqa: F401  (imported once here, before the workers fork, instead of once in each)

        if any(t[1].kind == "impact-outcome" for t in plan):  # likewise numba, where the batch engine will use it
            from ..solve.compiled import available

            available()
    with process_pool(jobs) as pool:
        t0 = time.perf_counter()
        results, done = _run(plan, functools.partial(_fit_task, timeout=fit_timeout), pool, progress, 0, total,
                             label)
        fits += results
        fits.sort(key=lambda f: (order[f.datasets[0]], law_names.index(f.law), family(f.solver) == "series"))
        timings["fits"] = time.perf_counter() - t0
        if all(f.status == "skipped" for f in fits):
            reasons = list(dict.fromkeys(f.reason for f in fits))
            raise FrictionLabError("compare: no fit could be made: " + "; ".join(reasons[:3])
                                   + (f" (and {len(reasons) - 3} more reasons)" if len(reasons) > 3 else ""))
        eq_results = []
        if eq_pairs:
            t0 = time.perf_counter()
            lookup = {(f.datasets[0], f.law, f.solver): f for f in fits}
            tasks, slow = [], []
            for d, (la, sa), (lb, sb) in eq_pairs:
                fa, fb = lookup[(d, la, sa)], lookup[(d, lb, sb)]
                why = _slow_pair(fa, fb, replicates) if not bootstrap_all else ""
                if why:
                    slow.append(EquivalenceResult(dataset=d, law_a=la, law_b=lb, solver_a=sa, solver_b=sb,
                                                  status="skipped", reason=why, replicates=replicates, seed=seed))
                else:
                    tasks.append((fa, fb, replicates, seed, fit_timeout))
            eq_results, done = _run(tasks, _equivalence_task, pool, progress, done, total,
                                    lambda t: f"equivalence on {t[0].datasets[0]}: {t[0].law} [{t[0].solver}] "
                                              f"vs {t[1].law} [{t[1].solver}]")
            done += len(slow)
            eq_results += slow
            timings["equivalence"] = time.perf_counter() - t0
        transfer_results = []
        if transfer:
            t0 = time.perf_counter()
            by_group = candidates_by_group(fits, dss)
            tasks = [(g, c, fs) for g, cands in by_group.items() for c, fs in cands.items()]
            parts, _ = _run([(fs, dict(free or {}), fit_timeout) for _, _, fs in tasks], _transfer_task, pool, None, 0,
                            0, str)
            for g, cands in by_group.items():
                transfer_results.append(assemble(g, cands, {c: p for (gg, c, _), p in zip(tasks, parts) if gg == g}))
            if by_group:
                timings["transfer"] = time.perf_counter() - t0
            transfer_results += _transfer.skipped(dss, fits=fits)
        step = _Step(progress, done, total)

        def tolerance_stage():
            t0 = time.perf_counter()
            options = ({"free": dict(free)} if free else {}) | ({"timeout": fit_timeout} if fit_timeout else {})
            rows = tolerance_check(fits, tuple(tolerance), pool, fit_options=options or None)
            step("tolerance check")
            timings["tolerance"] = time.perf_counter() - t0
            return rows

        side = ThreadPoolExecutor(1)  # with a pool, the tolerance fits queue there ahead of the bootstrap
        try:
            tol_future = side.submit(tolerance_stage) if tolerance and pool is not None else None
            if tolerance and pool is None:
                tol_rows = tolerance_stage()
            if bootstrap:
                t0 = time.perf_counter()
                boots, boot_skipped = bootstrap_fits(
                    fits, bootstrap, seed, pool, bootstrap_all, free, timeout=fit_timeout,
                    progress=lambda name, k, n: step(f"bootstrap on {name}: {k}/{n} resamples", advance=k == n))
                timings["bootstrap"] = time.perf_counter() - t0
            if tol_future is not None:
                tol_rows = tol_future.result()
        except BaseException:  # ^C, SIGTERM, a crash: do not wait for the side thread; the pool is stopped next
            side.shutdown(wait=False, cancel_futures=True)
            raise
        side.shutdown(wait=True)
    eq_results.sort(key=lambda e: (order[e.dataset], _pair_index(pairs, e), "series" in (e.solver_a, e.solver_b)))
    ranking = rank_fits(fits)
    kinds = {d.name: d.kind for d in dss}
    groups = rank_groups(ranking, kinds, named={d.name: group_of(d) for d in dss})
    answers = make_answers([d for d in dss if d.name not in skipped_ds], fits, ranking, groups)
    # the verdict layer's rows; the equivalence and transfer fields are filled by their producers
    answers = _transfer.fill_answers(_equivalence.fill_answers(answers, eq_results), transfer_results)
    answers += not_fitted_answers(dss, {k: v for k, v in skipped_ds.items() if k in no_law},
                                  [d for d in dss if d.name not in skipped_ds])
    return Comparison(laws=law_names, datasets=dss, fits=tuple(fits), ranking=tuple(ranking), groups=tuple(groups),
                      equivalence=tuple(eq_results), transfer=tuple(transfer_results), skipped_datasets=skipped_ds,
                      wall_time=time.perf_counter() - started, versions=versions(),
                      settings={"solvers": list(solvers) if solvers else "default", "jobs": jobs,
                                "equivalence": equivalence, "free": {k: list(v) for k, v in (free or {}).items()},
                                "bootstrap": int(bootstrap), "seed": int(seed), "bootstrap_all": bool(bootstrap_all),
                                "tolerance": [float(r) for r in tolerance], "fit_timeout": fit_timeout,
                                "replicates": int(replicates), "pairs": [list(p) for p in pairs],
                                "transfer": bool(transfer)},
                      bootstrap=tuple(boots), bootstrap_skipped=boot_skipped, tolerance=tuple(tol_rows),
                      timings=timings, answers=answers)


class _Step:
    """Advances the progress count by one per finished stage item (``advance=False``: only a new label)."""

    def __init__(self, progress, done, total):
        self.progress, self.done, self.total = progress, done, total

    def __call__(self, label: str, advance: bool = True) -> None:
        self.done += bool(advance)
        if self.progress:
            self.progress(self.done, self.total, label)


def _unique_datasets(dss) -> tuple[Dataset, ...]:
    """Datasets with repeats dropped; two different datasets under one name are an error."""
    out: dict[str, Dataset] = {}
    for ds in dss:
        if ds.name in out and out[ds.name].path != ds.path:
            raise FrictionLabError(f"compare: two datasets are named '{ds.name}' ({out[ds.name].path} and {ds.path}); "
                                   "names must be unique")
        out.setdefault(ds.name, ds)
    return tuple(out.values())


def _equivalence_pairs(law_names, plan, pairs) -> list[tuple[str, tuple[str, str], tuple[str, str]]]:
    """(dataset, (law A, solver), (law B, solver)) for every pair of ``pairs`` whose laws are both
    fitted on a dataset: each law with its full solver (exact or ode); the paper's pair (the first)
    also with law A's series."""
    names = {get_law(n).name for n in law_names}
    fitted: dict[str, dict[str, list[str]]] = {}
    for law, ds, solver, _ in plan:
        fitted.setdefault(ds.name, {}).setdefault(law, []).append(solver)
    out = []
    for d, laws in fitted.items():
        for i, (a, b) in enumerate(pairs):
            a, b = get_law(a).name, get_law(b).name
            if not {a, b} <= names or a not in laws or b not in laws:
                continue
            full_a = [s for s in laws[a] if family(s) == "full"]
            full_b = [s for s in laws[b] if family(s) == "full"]
            if not full_b:
                continue
            for sa in full_a + ([s for s in laws[a] if s == "series"] if i == 0 else []):
                out.append((d, (a, sa), (b, full_b[0])))
    return out


def _pair_index(pairs, e) -> int:
    for i, (a, b) in enumerate(pairs):
        if (get_law(a).name, get_law(b).name) == (e.law_a, e.law_b):
            return i
    return len(pairs)


def _slow_pair(fa: FitResult, fb: FitResult, replicates: int) -> str:
    """Why the parametric bootstrap of this pair is slow, or ''."""
    ode = [f for f in (fa, fb) if f.ok and f.solver.startswith("ode")]
    if ode:
        cpu = sum(f.cpu_time for f in ode)
        return (f"{' and '.join(f'{f.law} [{f.solver}]' for f in ode)} need{'s' * (len(ode) == 1)} the ODE solver "
                f"(its fit took {cpu:.1f} CPU s; the test refits both laws {4 * replicates} times); add "
                "--bootstrap-all to include it")
    if fa.ok and fa.per_dataset[0].target.t is None:
        return (f"an {fa.per_dataset[0].target.dataset.kind} set simulates every row at each evaluation "
                f"(the test refits both laws {4 * replicates} times); add --bootstrap-all to include it")
    return ""
