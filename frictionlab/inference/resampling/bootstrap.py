"""Bootstrap confidence intervals for fitted parameters, and how often each law ranks first.

``bootstrap(fit_fn, dataset, n, seed, executor)`` refits ``n`` resampled copies of a dataset (or
of a group of datasets, fitted together) and returns a ``BootstrapResult``:
  method='parametric' y* = best-fit model + Gaussian noise of the dataset's declared sigma (a
                     simulation from the fit, then a refit): the comparison's choice, valid for
                     time series (no resampling of correlated points) where sigma is known.
  method='residual'  y* = best-fit model + residuals of the original fit drawn with replacement
                     (centred); times, scene and noise estimate unchanged.
  method='case'      rows drawn with replacement (kept in time order): no model assumed; breaks
                     the time structure of a series, so only for independent rows.
Replicate r draws from its own generator, ``SeedSequence(seed).spawn(n)[r]``, inside the task that
fits it, so the numbers depend on the seed only, never on the executor, its workers or the order
in which tasks finish.

``executor`` is anything with ``submit(fn, *args) -> future`` whose futures have ``result()``:
None runs here, one replicate after another; a ``concurrent.futures`` executor; or a
``dask.distributed.Client`` (pip install 'frictionlab[dask]'; e.g. ``Client(LocalCluster())`` or
``Client('tcp://scheduler:8786')`` for a real cluster). Functions and datasets travel by pickle.

``bootstrap_ranking(laws, dataset, n, seed, executor)`` fits every law to the same resampled
copies and counts how often each ranks first by AIC (``ranking_bootstrap``). A law given with a solver
(``law_fit('wear', 'series')``) is its own candidate, labelled 'wear [series]', so the paper's
series and the exact solution of one law compete as they do in the comparison's ranking. Fits
already made on the original data can be passed (``base=``, ``bases=``) instead of being
repeated. ``parameter_table`` and ``ranking_table`` turn the results into rows for the report.
"""
from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import Executor
from typing import TYPE_CHECKING

import attrs
import numpy as np

from ...core.errors import FrictionLabError, ParameterError

if TYPE_CHECKING:  # annotations only
    from ...physics.law import FrictionLaw
    from ..fitting.result import FitResult
    from ..fitting.predict import DatasetLike

METHODS = ("parametric", "residual", "case")


# --- fitting functions that travel ---------------------------------------------------------------
@attrs.frozen
class LawFit:
    """A picklable fit function: ``fitting.fit(law, data, solver, **options)``.

    ``warm(values, n_params)`` returns a copy that starts from ``values`` with no grid scan and one
    Levenberg-Marquardt run, without the plausibility flags or the error analysis (``fit(checks=False,
    errors=False)``, its AIC counting the base fit's ``n_params``): replicates start at the original best
    fit, which is where the bootstrap asks how far the optimum moves, and read only values and AIC.
    """

    law: str
    solver: str = "auto"
    options: tuple = ()  # sorted (key, value) pairs of fitting.fit keyword arguments
    start: tuple = ()  # sorted (name, value) law-parameter start values, SI
    n_params: int | None = None  # a replicate's parameter count for its AIC: its base fit's
    name: str = ""  # the candidate's name when it differs from the law's (e.g. 'wear = couette')

    def __call__(self, data):
        from ..fitting.fit import fit

        kw = dict(self.options)
        if self.start:  # a replicate: only its values and AIC are read, so no plausibility flags
            kw.update(initial={**dict(kw.get("initial") or {}), **dict(self.start)}, scan=0, n_starts=1, checks=False,
                      errors=False, n_params=self.n_params)
        return fit(self.law, data, solver=self.solver, **kw)

    def warm(self, values: Mapping[str, float], n_params: int | None = None) -> "LawFit":
        return attrs.evolve(self, start=tuple(sorted(values.items())), n_params=n_params)

    @property
    def label(self) -> str:
        """The candidate's name: the law, with ' [solver]' when a solver was named."""
        name = self.name or self.law
        return name if self.solver == "auto" else f"{name} [{self.solver}]"


def law_fit(law: str | FrictionLaw, solver: str = "auto", **options: object) -> LawFit:
    """``LawFit`` for a law name and ``fitting.fit`` keyword options (free, fixed, local, ...)."""
    name = law if isinstance(law, str) else law.name
    return LawFit(name, solver, tuple(sorted(options.items())))


# --- results ---------------------------------------------------------------------------------------
@attrs.frozen(eq=False)
class BootstrapResult:
    """Bootstrap of one fit. samples (n, k) holds the fitted values of ``names`` (the parameters the
    data determine, ``FitResult.determined``) per replicate (NaN rows where the refit failed); aic (n,)
    the replicate's AIC."""

    law: str
    datasets: tuple[str, ...]
    method: str
    seed: int
    names: tuple[str, ...]
    units: tuple[str, ...]
    base: object  # the FitResult on the original data
    samples: np.ndarray
    aic: np.ndarray
    failures: tuple[str, ...]  # reasons, one per failed replicate

    @property
    def n(self) -> int:
        return self.samples.shape[0]

    @property
    def n_ok(self) -> int:
        return int(np.sum(np.all(np.isfinite(self.samples), axis=1))) if self.samples.size else self.n - len(self.failures)

    def interval(self, name: str, level: float = 0.95) -> tuple[float, float]:
        """Percentile interval [SI] of parameter ``name`` over the successful replicates."""
        col = self._column(name)
        if col.size == 0:
            return math.nan, math.nan
        a = (1.0 - level) / 2.0
        lo, hi = np.quantile(col, [a, 1.0 - a])
        return float(lo), float(hi)

    def std(self, name: str) -> float:
        col = self._column(name)
        return float(np.std(col, ddof=1)) if col.size > 1 else math.nan

    def _column(self, name):
        if name not in self.names:
            raise ParameterError(f"bootstrap of '{self.law}': no fitted parameter '{name}' (has: {', '.join(self.names)})")
        col = self.samples[:, self.names.index(name)]
        return col[np.isfinite(col)]


# --- resampling (runs inside the tasks) --------------------------------------------------------------
def _as_list(dataset):
    return list(dataset) if isinstance(dataset, (list, tuple)) else [dataset]


def _resample(datasets, models, method, rng):
    """Resampled copies of datasets; models[i] is dataset i's best-fit model of its observable."""
    out = []
    for ds, model in zip(datasets, models):
        cols = dict(ds.columns)
        if method == "case":
            idx = np.sort(rng.integers(0, len(ds), len(ds)))
            cols = {k: v[idx] for k, v in cols.items()}
        elif method == "parametric" and getattr(ds, "noise_correlation", "none") in ("ar1", "arp"):  # correlated
            from ..noise.record import noise_drawer

            cols[ds.observable] = model + noise_drawer(ds, ds.y, model, None)(rng)
        elif method == "parametric":
            cols[ds.observable] = model + rng.normal(0.0, ds.noise[ds.observable], model.shape)
        else:
            y = cols[ds.observable]
            res = y - model
            res = res - res.mean()
            cols[ds.observable] = model + res[rng.integers(0, res.size, res.size)]
        out.append(attrs.evolve(ds, columns=cols))
    return out


def _values(result, names):
    if not getattr(result, "ok", False):
        return None
    return [result.params[k].value if k in result.params else math.nan for k in names]


def _aic(result):
    stats = getattr(result, "stats", None)
    return float(stats.aic) if stats is not None and getattr(result, "ok", False) else math.nan


def _run_chunk(fit_fns, datasets, models, method, seeds):
    """Fit every function in fit_fns to the replicates of seeds; returns, per seed, per function,
    (values or None, aic, failure reason). A warm-started law's refits of every seed are made together where a
    batched route serves (``_batched``), the others one at a time."""
    single = len(datasets) == 1
    data = [_resample(datasets, models, method, np.random.default_rng(seed)) for seed in seeds]
    cols = [_batched(fn, names, datasets, method, data) if single else None for fn, names in fit_fns]
    out = []
    for r, replicate in enumerate(data):
        row = []
        for (fn, names), col in zip(fit_fns, cols):
            if col is not None and col[r] is not None:
                row.append(col[r])
                continue
            try:
                res = fn(replicate[0] if single else replicate)
                vals = _values(res, names)
                row.append((vals, _aic(res), "" if vals is not None else (getattr(res, "reason", "") or "fit failed")))
            except FrictionLabError as exc:
                row.append((None, math.nan, str(exc)))
        out.append(row)
    return out


#: LawFit options a batched refit reproduces (``_batched``); any other keeps the refits one at a time.
BATCHED_OPTIONS = frozenset({"fixed", "initial", "timeout", "rtol", "max_nfev"})


def _batched(fn, names, datasets, method, data) -> list | None:
    """Per replicate of ``data`` (one dataset each) ``fn``'s row (values, aic, '') from one batched refit
    (``batchfit.refit_many``), None for a replicate it did not serve; None where no batched route serves: a
    parametric bootstrap of a warm-started law (``LawFit.warm``) with options the batch reproduces."""
    from ..fitting import batch as batchfit
    from ..fitting.stats import neg2loglik, noise_kind
    from ...solve.choice import auto_solver
    from ..fitting.predict import make_target
    from .replicates import batch_problem

    if not (isinstance(fn, LawFit) and fn.start and method == "parametric"
            and set(dict(fn.options)) <= BATCHED_OPTIONS):
        return None
    ds, opts = datasets[0], dict(fn.options)
    try:
        target = make_target(ds, None, None)
        solver = auto_solver(fn.law, ds.scene) if fn.solver == "auto" else fn.solver
    except FrictionLabError:
        return None
    refit = {"solver": solver, "fixed": opts.get("fixed") or {},
             "initial": {**dict(opts.get("initial") or {}), **dict(fn.start)}}
    pr = batch_problem(fn.law, refit, target)
    if pr is None:
        return None
    got = batchfit.refit_many(pr, np.array([d[0].y for d in data]))
    if got is None:
        return None
    k = len(pr.slots) if fn.n_params is None else int(fn.n_params)
    kind = noise_kind(target)
    out = []
    for i in range(len(data)):
        if not got.ok[i]:
            out.append(None)
            continue
        vals = [float(got.values[n][i]) if n in got.values else math.nan for n in names]
        out.append((vals, neg2loglik(float(got.chisqr[i]), target.y.size, target.sigma, kind) + 2 * k, ""))
    return out


def _guarded_chunk(fit_fns, datasets, models, method, seeds):
    """``_run_chunk``, in a child ended past the refits' time budget when a candidate is a third-party law
    (``inference.fitting.guard``); then every refit of the chunk failed with that reason."""
    from ..fitting.guard import within_budget

    timeout = min((dict(fn.options).get("timeout") or math.inf for fn, _ in fit_fns), default=math.inf)
    over = lambda why: [[(None, math.nan, why)] * len(fit_fns) for _ in seeds]  # noqa: E731
    return within_budget(_run_chunk, [fn.law for fn, _ in fit_fns], None if math.isinf(timeout) else timeout,
                         fit_fns, datasets, models, method, seeds, over=over)


def _dispatch(executor, fit_fns, datasets, models, method, seed, n, chunk, progress=None):
    """Rows of _run_chunk over n resamples in batches of ``chunk``; progress(done, n) after each batch."""
    seeds = np.random.SeedSequence(seed).spawn(n)
    # run here, the replicates are one chunk, so that a law's refits of them are one batch (``_batched``)
    chunk = max(1, int(chunk or (math.ceil(n / 16) if executor is not None else n)))
    groups = [seeds[i:i + chunk] for i in range(0, n, chunk)]
    parts, done = [], 0
    futures = None if executor is None else [executor.submit(_guarded_chunk, fit_fns, datasets, models, method, g)
                                             for g in groups]
    for i, g in enumerate(groups):
        parts.append(_guarded_chunk(fit_fns, datasets, models, method, g) if futures is None else futures[i].result())
        done += len(g)
        if progress:
            progress(done, n)
    return [row for part in parts for row in part]


def _prepare(fit_fn, dataset, method, base=None):
    from ...io.dataset import load_dataset

    if method not in METHODS:
        raise ParameterError(f"bootstrap: method must be one of {', '.join(METHODS)}, got {method!r}")
    datasets = [load_dataset(d) for d in _as_list(dataset)]
    if base is None:
        base = fit_fn(datasets[0] if len(datasets) == 1 else datasets)
    elif tuple(getattr(base, "datasets", ())) != tuple(d.name for d in datasets):
        raise ParameterError(f"bootstrap: the given fit is of {', '.join(getattr(base, 'datasets', ()))}, "
                             f"not of {', '.join(d.name for d in datasets)}")
    if not getattr(base, "ok", False):
        raise FrictionLabError(f"bootstrap: the fit on the original data did not succeed "
                               f"({getattr(base, 'reason', '') or getattr(base, 'status', 'failed')})")
    models = [None] * len(datasets)
    if method in ("residual", "parametric"):
        for i, ds in enumerate(datasets):
            part = next((p for p in base.per_dataset if p.target.name == ds.name), None)
            if part is None or part.target.derivation or part.target.observable != ds.observable \
                    or part.model.shape != ds.y.shape:
                raise FrictionLabError(f"bootstrap: dataset '{ds.name}' was not fitted on its own observable column; "
                                       "use method='case'")
            models[i] = part.model
    names = base.determined
    units = tuple(base.params[k].unit for k in names)
    law_values = {p.key: p.value for p in base.params.values() if p.vary and p.kind == "law"}
    replicate_fn = fit_fn.warm(law_values, base.stats.n_params) if isinstance(fit_fn, LawFit) else fit_fn
    return datasets, base, models, names, units, replicate_fn


def _collect(law, datasets, method, seed, names, units, base, rows, k):
    samples = np.full((len(rows), len(names)), np.nan)
    aic = np.full(len(rows), np.nan)
    failures = []
    for r, row in enumerate(rows):
        vals, a, why = row[k]
        if vals is None:
            failures.append(why)
        else:
            samples[r] = vals
            aic[r] = a
    return BootstrapResult(law=law, datasets=tuple(d.name for d in datasets), method=method, seed=seed, names=names,
                           units=units, base=base, samples=samples, aic=aic, failures=tuple(failures))


def _check_n(n, seed):
    if not (isinstance(n, (int, np.integer)) and n >= 1):
        raise ParameterError(f"bootstrap: n must be a positive integer, got {n!r}")
    if not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ParameterError(f"bootstrap: seed must be a non-negative integer, got {seed!r}")


# --- public API -----------------------------------------------------------------------------------------
def bootstrap(fit_fn: Callable[..., FitResult], dataset: DatasetLike | Sequence[DatasetLike], n: int = 200,
              seed: int = 0, executor: Executor | None = None, method: str = "residual", chunk: int | None = None,
              base: FitResult | None = None) -> BootstrapResult:
    """Refit ``n`` resampled copies of ``dataset`` (a Dataset, name or path, or a list fitted together).

    fit_fn(data) -> FitResult, e.g. ``law_fit('wear', solver='exact')`` (warm-started replicates) or
    any picklable callable. chunk: replicates per submitted task (default: n / 16 with an executor, n without;
    at least 1).
    base: fit_fn's FitResult on the original data, if already made (else it is fitted here).
    """
    _check_n(n, seed)
    datasets, base, models, names, units, rfn = _prepare(fit_fn, dataset, method, base)
    rows = _dispatch(executor, [(rfn, names)], datasets, models, method, seed, n, chunk)
    return _collect(base.law, datasets, method, seed, names, units, base, rows, 0)
