"""Compare laws on datasets: ``compare`` runs the named stages of ``stages.STAGES`` over one ``Comparison``.

``compare(laws=None, datasets=None, solvers=None)`` with no arguments compares the four laws of the
paper on every built-in dataset. Solvers: by default each law is solved 'exact' where a closed
form exists for the dataset's scene, else 'ode', and additionally 'series' where the paper's
expansion applies; an explicit list fits each solver that applies (the others are recorded as
skipped with the reason). Contact-area datasets are supporting series and are not fitted; a
dataset kind without a predictor is skipped with that reason (``planning``). Nothing here raises for
a fit that fails: it becomes a row with status 'failed' and its reason.

The stages, in order (``stages.py``): fit, rank, equivalence (the discrimination test on the pairs of
``equivalence.PAIRS``), transfer (one parameter set across a group), tolerance (ODE laws refitted at
other tolerances), accuracy (what each solver's accuracy costs), bootstrap (parametric replicates: intervals and first-place shares), answer (the
verdict rows of the first screen). ``runner.run_stages`` holds the pool, the clock and the progress
count around them; ``run_stages`` below continues a comparison with more stages.
"""
from __future__ import annotations

import os
import platform
import time
from collections.abc import Sequence
from typing import TYPE_CHECKING

import attrs
import numpy as np

from ..core.arguments import as_items
from ..core.blas import one_blas_thread
from ..core.errors import FrictionLabError, ParameterError
from ..inference.equivalence.discrimination import REPLICATES, EquivalenceResult
from ..inference.fitting.fit import FitResult, scene_ranges
from ..inference.equivalence.margin import MARGIN
from ..inference.verdicts.ranking import RankRow
from ..inference.equivalence.transfer import TransferResult
from ..io.dataset import Dataset, available_names, check_dataset_like, load_dataset
from .planning import (  # noqa: F401
    candidates,
    equivalence_pairs,
    no_law_applies,
    plan_fits,
    unique_datasets,
)
from .perdataset import run_per_dataset
from .runner import Progress, Run, select
from .runner import run_stages as run_stages_with
from .settings import DEFAULT_LAWS, DEFAULT_LAWS_BY_KIND, Settings, check_pairs, default_laws_by_kind, select_laws  # noqa: F401
from .stages import STAGES
from ..core.fpstate import with_own_errstate

if TYPE_CHECKING:  # annotations only
    import pandas as pd
    from dask.distributed import Client
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure


@attrs.frozen(eq=False)
class Comparison:
    """What `compare` returns: everything a report needs.

    Attributes
    ----------
    laws : tuple of str
        The laws compared.
    datasets : tuple of Dataset
        Every dataset asked for, fitted or not (``skipped_datasets`` says why one was not).
    fits : tuple of FitResult
        Every fit, per dataset, law and solver.
    ranking : tuple of RankRow
        The ranking per dataset; ``groups`` the same over each group of datasets.
    equivalence : tuple of EquivalenceResult
        The equivalence verdicts, law A against law B per dataset.
    answers : tuple
        The answer per dataset group: the report's first screen.
    settings : dict
        The options the comparison ran with, as ``results.json`` writes them.
    wall_time : float
        Wall-clock time of the comparison [s].
    """

    laws: tuple[str, ...]
    datasets: tuple[Dataset, ...]  # every dataset asked for, fitted or not
    fits: tuple[FitResult, ...]
    ranking: tuple[RankRow, ...]  # per dataset
    groups: tuple[RankRow, ...]  # each declared dataset group of two or more
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
    options: Settings | None = None  # the settings as a record (``settings`` is the same as results.json writes it)
    accuracy: tuple = ()  # accuracy.SolverCost rows: each solver's error and time per law and dataset

    def fit_for(self, dataset: str, law: str, solver: str | None = None) -> FitResult | None:
        """The fit of one law to one dataset.

        Parameters
        ----------
        dataset : str
            The dataset's name.
        law : str
            The law's name.
        solver : str, optional
            The solver (``"exact"``, ``"series"``, ``"ode"``); any when None.

        Returns
        -------
        FitResult or None
            The fit, or None when there is none.
        """
        for f in self.fits:
            if f.datasets == (dataset,) and f.law == law and (solver is None or f.solver == solver):
                return f
        return None

    def fits_on(self, dataset: str) -> list[FitResult]:
        """Every fit to one dataset alone.

        Parameters
        ----------
        dataset : str
            The dataset's name.

        Returns
        -------
        list of FitResult
            Its fits, by law and solver.
        """
        return [f for f in self.fits if f.datasets == (dataset,)]

    def dataset(self, name: str) -> Dataset:
        """The compared dataset called ``name``.

        Parameters
        ----------
        name : str
            The dataset's name.

        Returns
        -------
        Dataset
            The dataset.

        Raises
        ------
        StopIteration
            No compared dataset has that name.
        """
        return next(d for d in self.datasets if d.name == name)

    @property
    def fitted_datasets(self) -> list[Dataset]:
        """The datasets that were fitted (not left out with a reason)."""
        return [d for d in self.datasets if d.name not in self.skipped_datasets]

    def to_dataframe(self) -> pd.DataFrame:
        """The ranking as a tidy table.

        Returns
        -------
        pandas.DataFrame
            One row per dataset and candidate (law, solver): rank, fits, rss and rmse with their units,
            reduced chi-square, AIC, AICc, BIC, delta AIC, Akaike weight, reason; the rows of the groups the
            datasets declare after them.
        """
        from ..inference.fitting.frames import ranking_frame

        return ranking_frame(self)

    def parameters_dataframe(self) -> pd.DataFrame:
        """Every fitted parameter as a tidy table.

        Returns
        -------
        pandas.DataFrame
            One row per dataset, law, solver and parameter: value and stderr (SI), unit, kind, vary,
            fixed_by, lower, upper.
        """
        from ..inference.fitting.frames import parameters_frame

        return parameters_frame(self.fits)

    def __repr__(self) -> str:
        ok = sum(f.ok for f in self.fits)
        best = "; ".join(f"{d.name}: " + " = ".join(r.candidate for r in self.ranking if r.dataset == d.name
                                                    and r.rank == 1) for d in self.fitted_datasets[:3])
        more = f"; ... {len(self.fitted_datasets) - 3} more" if len(self.fitted_datasets) > 3 else ""
        return (f"<Comparison of {len(self.laws)} laws on {len(self.fitted_datasets)} datasets: {ok} fits; "
                f"lowest AIC: {best}{more}>")

    def plot(self, ax: Axes | Sequence[Axes] | None = None, top: int = 3) -> Figure | Axes | Sequence[Axes]:
        """What the report's first screen shows per dataset group, as one figure.

        For each group (its first fitted dataset), the data with the ``top`` top-ranked candidates above and
        their residuals in units of sigma below, each labelled with its rank and whether it passes its
        goodness-of-fit tests.

        Parameters
        ----------
        ax : matplotlib.axes.Axes or sequence of them, optional
            One Axes per group: the data and fits only, drawn there.
        top : int, default 3
            How many candidates to draw per group.

        Returns
        -------
        matplotlib.figure.Figure or Axes
            The new figure, or ``ax`` when given.
        """
        from ..inference.verdicts.answers import group_of
        from ..inference.fitting.plots import fits_text, plot_ranking

        panels, seen = [], set()
        for d in self.fitted_datasets:
            group = group_of(d)
            rows = sorted((r for r in self.ranking if r.dataset == d.name and r.rank is not None), key=lambda r: r.rank)
            fits = [(self.fit_for(d.name, r.law, r.solver), r) for r in rows]
            fits = [(f.per_dataset[0], f"{r.rank}. {r.candidate}: fits? {fits_text(r.goodness)}")
                    for f, r in fits if f is not None and f.ok]
            if group in seen or not fits:
                continue
            seen.add(group)
            panels.append((group if group == d.name else f"{group}: {d.name}", fits))
        return plot_ranking(panels, ax, top)

    def _repr_html_(self) -> str:
        from ..inference.fitting.frames import comparison_html

        return comparison_html(self)


def versions() -> dict:
    import lmfit
    import matplotlib
    import scipy

    from ..core import __version__

    return {"frictionlab": __version__, "python": platform.python_version(), "numpy": np.__version__,
            "scipy": scipy.__version__, "lmfit": lmfit.__version__, "matplotlib": matplotlib.__version__,
            "platform": platform.platform(), "cpus": os.cpu_count()}


@with_own_errstate
@one_blas_thread
def compare(laws: Sequence[str] | None = None, datasets: Sequence | None = None, solvers: Sequence[str] | None = None,
            *, free: dict | None = None, equivalence: bool = True, jobs: int = 1,
            progress: Progress | None = None, bootstrap: int = 0, seed: int = 0, bootstrap_all: bool = False,
            tolerance: Sequence[float] = (), fit_timeout: float | None = None, replicates: int = REPLICATES,
            pairs: Sequence | None = None, transfer: bool = True, stages: Sequence[str] | None = None,
            client: Client | None = None, margin: float | str = MARGIN, family: str = "report",
            accuracy: bool = True) -> Comparison:
    """Fit every law to every dataset with every applicable solver, rank, and test the equivalence.

    The command line's ``frictionlab compare`` differs in two defaults (said in its ``--help``): bootstrap 150
    and fit_timeout 900 s; here each runs only when asked for.

    Parameters
    ----------
    laws : sequence of str or "all", optional
        Registered names; None for the default laws of each dataset kind (Coulomb, area-rate, wear and Couette
        on impacts and inclines; rate-and-state aging, slip, PRZ and Nagata on spring-sliders); "all" for every registered
        law.
    datasets : sequence, optional
        Built-in names, names of measured records, TOML paths or Datasets; default every built-in dataset and
        every measured record present.
    solvers : sequence of str, optional
        ``"exact"``, ``"series"``, ``"ode[:METHOD]"``, ``"auto"``; None for the default choice per law.
    free : dict, optional
        Scene quantities fitted per dataset: name -> bounds, ``"low:high"`` with units or a tuple of SI
        numbers, quantity strings or pint Quantities (``u0`` [m/s], ...).
    equivalence : bool, default True
        Run the equivalence tests of ``pairs``.
    jobs : int, default 1
        Worker processes.
    progress : Progress, optional
        Called as ``progress(done, total, label)``.
    bootstrap : int, default 0
        Parametric replicates of the ranking per dataset (0: none), drawn from ``seed``.
    seed : int, default 0
        Seed of every random draw (bootstrap, replicates).
    bootstrap_all : bool, default False
        Also bootstrap and test datasets where a law needs the ODE, or without a time series.
    tolerance : sequence of float, default ()
        Looser ODE tolerances at which the ODE laws of one dataset are refitted (empty: no check).
    fit_timeout : float, optional
        Time budget of each fit [s], its refits included; a fit past it is a failed row saying so.
    replicates : int
        Replicates per law of the equivalence test's parametric bootstrap.
    pairs : sequence of (str, str) or "LAW:LAW" strings, optional
        The pairs of laws to test, each two different compared laws, each tested once whatever its order;
        None: ``equivalence.PAIRS``, those whose laws are both compared.
    transfer : bool, default True
        Run the transfer stage (parameters fitted on one dataset of a group predicting the others).
    stages : sequence of str, optional
        The stages to run (fit, rank, equivalence, transfer, tolerance, bootstrap, answer); None for every
        stage the options switch on. `run_stages` runs more of them on the result later.
    client : distributed.Client, optional
        A Dask client: fits, refits, tests and bootstrap run on its workers instead of ``jobs`` local
        processes (the same numbers either way).
    margin : float, str or pint Quantity, default 1
        The equivalence margin delta: a positive multiple of each dataset's noise sigma, or a positive quantity
        in the observable's unit (``"150 rpm"``); refused with ``equivalence=False``.
    family : {"report", "group"}, default "report"
        Holm's adjustment over every hypothesis of the report, or within each dataset group only.
    accuracy : bool, default True
        Measure what accuracy costs (each solver's error and time against the most accurate one at the fitted
        parameters) where it is cheap; with ``tolerance`` given, everywhere.

    Returns
    -------
    Comparison
        The fits, rankings, equivalence verdicts and answers; `write_report` writes it as a report.

    Raises
    ------
    FrictionLabError
        An unknown law or dataset, a dataset that does not load, or an option out of range (the message
        names it).

    Examples
    --------
    >>> import frictionlab as fl
    >>> c = fl.compare(laws=["wear", "coulomb"], datasets=["impact-golf-v28"], equivalence=False)
    >>> table = c.to_dataframe()
    >>> print(table[table.dataset == "impact-golf-v28"][["candidate", "rank", "fits"]].to_string(index=False))
          candidate  rank  fits
      wear [series]     1  True
       wear [exact]     2 False
    coulomb [exact]     3 False
    """
    started = time.perf_counter()
    settings = Settings(laws=(), solvers=tuple(solvers) if solvers else None,
                        free=scene_ranges(free, "compare: free"), equivalence=equivalence, jobs=jobs, bootstrap=bootstrap, seed=seed,
                        bootstrap_all=bootstrap_all, tolerance=tuple(tolerance), fit_timeout=fit_timeout,
                        replicates=replicates, transfer=transfer, cluster=cluster_name(client),
                        margin=margin, family=family, accuracy=accuracy)
    chosen = select(STAGES, stages)
    dss = unique_datasets(_dataset(d) for d in (as_items(datasets, "compare: datasets") if datasets is not None
                                                else available_names()))
    if not dss:
        raise FrictionLabError("compare: no datasets to compare")
    if laws is None:  # the default laws of each dataset kind
        by_kind = default_laws_by_kind(d.kind for d in dss)
        settings = attrs.evolve(settings, laws=tuple(dict.fromkeys(n for v in by_kind.values() for n in v)),
                                by_kind=by_kind)
    else:
        settings = attrs.evolve(settings, laws=select_laws(laws))
    if pairs is not None:
        groups = [settings.laws] if laws is not None else list(settings.by_kind.values())
        settings = attrs.evolve(settings, pairs=check_pairs(pairs, groups))
    if equivalence:
        settings.margin.check(dss)
    elif not settings.margin.default or pairs is not None:
        what = f"margin {settings.margin.as_text()!r} applies" if not settings.margin.default else "pairs apply"
        raise ParameterError(f"compare: {what} to the equivalence tests, which equivalence=False skips; drop one of "
                             "the two")
    run = _make_run(settings, dss, progress, client)
    settings.check_replicates()
    c = Comparison(laws=settings.laws, datasets=dss, fits=run.plan.skipped_fits, ranking=(), groups=(),
                   equivalence=(), skipped_datasets=run.plan.skipped_datasets, wall_time=0.0, versions=versions(),
                   settings=settings.as_dict(), options=settings)
    if jobs > 1 and client is None:
        _import_before_fork(run)
    c = _run_stages(c, run, chosen, forced=stages is not None)
    return attrs.evolve(c, wall_time=time.perf_counter() - started)


@with_own_errstate
def run_stages(comparison: Comparison, stages: Sequence[str], *, progress: Progress | None = None,
               client: Client | None = None, **options: object) -> Comparison:
    """Run the named stages (``stages.STAGES``) on a comparison made by ``compare``, e.g.
    ``run_stages(c, ["bootstrap", "answer"], bootstrap=150)``; ``options`` override the comparison's
    settings (the keyword arguments of ``compare``). Returns a new Comparison."""
    settings = attrs.evolve(comparison.options, **options, cluster=cluster_name(client))
    run = _make_run(settings, comparison.datasets, progress, client)
    c = attrs.evolve(comparison, settings=settings.as_dict(), options=settings)
    return _run_stages(c, run, select(STAGES, stages), forced=True)


def _run_stages(c: Comparison, run: Run, stages: list, forced: bool) -> Comparison:
    """``runner.run_stages``; on a cluster, a run that fits goes first in one task per dataset (``perdataset``)."""
    chosen = [s for s in stages if forced or s.wanted(run)]
    if run.client is not None and any(s.name == "fit" for s in chosen):
        c, chosen = run_per_dataset(c, run, chosen)
    return run_stages_with(c, run, chosen, forced=True)


def _dataset(d) -> Dataset:
    """A dataset argument of compare loaded, or checked still to be what loading made of it (``io.intact``)."""
    check_dataset_like(d, "compare: datasets")
    return load_dataset(d).check("compare")


def cluster_name(client) -> str:
    """How the report names a Dask cluster: its scheduler's address and number of workers ("" without one)."""
    if client is None:
        return ""
    from ..core.cluster import address_of, waits_of, worker_count

    workers = worker_count(client, waits_of(client).connect)  # asked within the cluster's connect time
    return f"Dask cluster at {address_of(client)} ({workers} worker{'s' * (workers != 1)})"


def _make_run(settings: Settings, dss, progress, client=None) -> Run:
    """The plan of the fits and tests (each stage counts its own items for the progress)."""
    plan = plan_fits(settings.laws, dss, settings.solvers, settings.free, settings.by_kind)
    eq_pairs = equivalence_pairs(settings.laws, plan.tasks, settings.pairs) if settings.equivalence else []
    return Run(settings=settings, plan=plan, eq_pairs=eq_pairs, progress=progress, client=client)


def _import_before_fork(run: Run) -> None:
    """lmfit (and numba, where the batch engine will use it) imported once here, before the workers fork,
    instead of once in each; and the velocity-step fit's kernels compiled (or loaded from numba's cache) here
    where the run fits a spring-slider with a rate-and-state law: on a first run each worker compiled them."""
    import lmfit  # noqa: F401

    if any(t[1].kind == "impact-outcome" for t in run.plan.tasks):
        from ..solve.compiled import available

        available()
    from ..solve.quasistatic import FITTED, compile_kernel

    if any(t[1].kind == "spring-slider" and t[0] in FITTED for t in run.plan.tasks):
        from ..inference.velstep.kernel import compile_sums

        compile_kernel()
        compile_sums()
