"""Compare laws on datasets: every (law, dataset, solver) fitted, ranked, and the equivalence tested.

``compare(laws=None, datasets=None, solvers=None)`` with no arguments compares every registered
law on every built-in dataset. Solvers: by default each law is solved 'exact' where a closed
form exists for the dataset's scene, else 'ode', and additionally 'series' where the paper's
expansion applies; an explicit list fits each solver that applies (the others are recorded as
skipped with the reason). Contact-area datasets are supporting series and are not fitted; a
dataset kind without a predictor is skipped with that reason. Nothing here raises for a fit
that fails: it becomes a row with status 'failed' and its reason.
"""
from __future__ import annotations

import os
import platform
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context

import attrs
import numpy as np

from .dataset import Dataset, builtin_names, load_dataset
from .equivalence import AREA_RATE, WEAR, EquivalenceResult, analyze_equivalence
from .errors import FrictionLabError
from .fitting import PREDICTORS, FitResult, applicable_solvers, auto_solver, fit
from .ranking import RankRow, family, rank_fits, rank_groups
from .registry import available_laws, get_law

Progress = Callable[[int, int, str], None]


@attrs.frozen(eq=False)
class Comparison:
    """Everything a report needs: fits, rankings, equivalence results, and what was left out."""

    laws: tuple[str, ...]
    datasets: tuple[Dataset, ...]  # every dataset asked for, fitted or not
    fits: tuple[FitResult, ...]
    ranking: tuple[RankRow, ...]  # per dataset
    groups: tuple[RankRow, ...]  # ALL and ALL[kind]
    equivalence: tuple[EquivalenceResult, ...]
    skipped_datasets: dict  # name -> reason
    wall_time: float
    versions: dict
    settings: dict

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


def versions() -> dict:
    import lmfit
    import matplotlib
    import scipy

    from . import __version__

    return {"frictionlab": __version__, "python": platform.python_version(), "numpy": np.__version__,
            "scipy": scipy.__version__, "lmfit": lmfit.__version__, "matplotlib": matplotlib.__version__,
            "platform": platform.platform(), "cpus": os.cpu_count()}


def candidates(law, dataset: Dataset, solvers: Sequence[str] | None) -> list[tuple[str, str | None]]:
    """(solver, reason it does not apply or None) for ``law`` on ``dataset``."""
    law = get_law(law)
    ok = applicable_solvers(law, dataset.scene)
    if solvers is None:
        out = [(auto_solver(law, dataset.scene), ok["ode"])]
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


def _fit_task(args) -> FitResult:
    law, dataset, solver, free = args
    try:
        return fit(law, dataset, solver=solver, free=free)
    except FrictionLabError as exc:  # e.g. a freed scene quantity this scene does not have
        return FitResult(law=law, solver=solver, datasets=(dataset.name,), status="skipped", reason=str(exc))


def _equivalence_task(args) -> EquivalenceResult:
    return analyze_equivalence(*args)


def _run(tasks, fn, jobs, progress, done, total, label):
    """Run fn over tasks, in a process pool when jobs > 1; results in task order."""
    results = [None] * len(tasks)
    if jobs > 1 and len(tasks) > 1:
        try:
            ctx = get_context("fork")
        except ValueError:  # no fork on this platform: run serially
            ctx = None
        if ctx is not None:
            with ProcessPoolExecutor(max_workers=jobs, mp_context=ctx) as pool:
                futures = {pool.submit(fn, t): i for i, t in enumerate(tasks)}
                from concurrent.futures import as_completed

                for fut in as_completed(futures):
                    i = futures[fut]
                    results[i] = fut.result()
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


def compare(laws: Sequence[str] | None = None, datasets: Sequence | None = None, solvers: Sequence[str] | None = None,
            *, free: dict | None = None, equivalence: bool = True, jobs: int = 1,
            progress: Progress | None = None) -> Comparison:
    """Fit every law to every dataset with every applicable solver, rank, and test the equivalence.

    laws: registered names (default all); datasets: built-in names, TOML paths or Datasets
    (default every built-in); solvers: None for the default choice, or a list of 'exact',
    'series', 'ode[:METHOD]', 'auto'; free: scene quantities fitted per dataset, name -> (lower,
    upper) in SI (see fitting.SCENE_QUANTITIES); jobs: worker processes; progress(done, total, label).
    """
    started = time.perf_counter()
    from .solvers import parse_solver

    for s in solvers or ():
        if s != "auto":
            parse_solver(s)  # an unknown solver is an input error, before any work
    law_names = tuple(dict.fromkeys(get_law(n).name for n in (laws or available_laws())))
    dss = _unique_datasets(load_dataset(d) for d in (datasets if datasets is not None else builtin_names()))
    if not dss:
        raise FrictionLabError("compare: no datasets to compare")
    skipped_ds, plan, fits = {}, [], []
    for ds in dss:
        if ds.kind == "contact-area":
            skipped_ds[ds.name] = "contact-area series: supporting data (the area model of a scene), not fitted"
            continue
        if ds.kind not in PREDICTORS:
            skipped_ds[ds.name] = f"no predictor for dataset kind '{ds.kind}' yet"
            continue
        for law in law_names:
            for solver, why in candidates(law, ds, solvers):
                if why:
                    fits.append(FitResult(law=law, solver=solver, datasets=(ds.name,), status="skipped", reason=why))
                else:
                    plan.append((law, ds, solver, dict(free or {})))
    if len(skipped_ds) == len(dss):
        raise FrictionLabError("compare: none of the datasets can be fitted: "
                               + "; ".join(f"{k}: {v}" for k, v in skipped_ds.items()))
    # slow (ode) fits first, so that workers finish together
    plan.sort(key=lambda x: not x[2].startswith("ode"))
    eq_pairs = _equivalence_pairs(law_names, plan) if equivalence else []
    total = len(plan) + len(eq_pairs)
    label = lambda t: f"{t[0]} [{t[2]}] on {t[1].name}"  # noqa: E731
    results, done = _run(plan, _fit_task, jobs, progress, 0, total, label)
    fits += results
    eq_results = []
    if eq_pairs:
        lookup = {(f.datasets[0], f.law, f.solver): f for f in fits}
        tasks = [(lookup[(d, WEAR, s)], lookup[(d, AREA_RATE, sa)]) for d, s, sa in eq_pairs]
        eq_results, done = _run(tasks, _equivalence_task, jobs, progress, done, total,
                                lambda t: f"equivalence on {t[0].datasets[0]} [{t[0].solver}]")
    order = {d.name: i for i, d in enumerate(dss)}
    eq_results.sort(key=lambda e: (order[e.dataset], family(e.solver) == "series"))
    fits.sort(key=lambda f: (order[f.datasets[0]], law_names.index(f.law), family(f.solver) == "series"))
    ranking = rank_fits(fits)
    kinds = {d.name: d.kind for d in dss}
    groups = rank_groups(ranking, kinds)
    return Comparison(laws=law_names, datasets=dss, fits=tuple(fits), ranking=tuple(ranking), groups=tuple(groups),
                      equivalence=tuple(eq_results), skipped_datasets=skipped_ds,
                      wall_time=time.perf_counter() - started, versions=versions(),
                      settings={"solvers": list(solvers) if solvers else "default", "jobs": jobs,
                                "equivalence": equivalence, "free": {k: list(v) for k, v in (free or {}).items()}})


def _unique_datasets(dss) -> tuple[Dataset, ...]:
    """Datasets with repeats dropped; two different datasets under one name are an error."""
    out: dict[str, Dataset] = {}
    for ds in dss:
        if ds.name in out and out[ds.name].path != ds.path:
            raise FrictionLabError(f"compare: two datasets are named '{ds.name}' ({out[ds.name].path} and {ds.path}); "
                                   "names must be unique")
        out.setdefault(ds.name, ds)
    return tuple(out.values())


def _equivalence_pairs(law_names, plan) -> list[tuple[str, str, str]]:
    """(dataset, wear solver, area-rate solver) for every dataset where both laws are fitted."""
    if WEAR not in law_names or AREA_RATE not in law_names:
        return []
    out = []
    for law, ds, solver, _ in plan:
        if law != WEAR:
            continue
        ar = [s for (lw, d, s, _) in plan if lw == AREA_RATE and d.name == ds.name]
        if ar:
            out.append((ds.name, solver, ar[0]))
    return out
