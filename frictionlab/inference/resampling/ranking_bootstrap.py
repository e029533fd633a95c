"""How often each law ranks first over bootstrap replicates, the comparison's parametric bootstrap of its
fits, and the tables the report shows (see ``bootstrap`` for the resampling itself)."""
from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import attrs
import numpy as np

from ...core.errors import FrictionLabError, ParameterError
from .bootstrap import _aic, _check_n, _collect, _dispatch, _prepare, BootstrapResult, law_fit, LawFit, METHODS


@attrs.frozen(eq=False)
class RankingBootstrap:
    """How often each candidate ranks first (lowest AIC) over paired resamples; per candidate a
    BootstrapResult. Candidates are labelled as ``LawFit.label``: the law, or 'law [solver]'."""

    laws: tuple[str, ...]  # candidate labels
    datasets: tuple[str, ...]
    first: dict  # label -> number of replicates it ranked first (ties within tie AIC split evenly)
    n_ranked: int  # replicates where every candidate's refit succeeded
    results: dict  # label -> BootstrapResult

    def fraction(self, law: str) -> float:
        return self.first[law] / self.n_ranked if self.n_ranked else math.nan


def bootstrap_ranking(laws: Sequence, dataset, n: int = 200, seed: int = 0, executor=None, solver: str = "auto",
                      method: str = "case", chunk: int | None = None, tie: float | None = None,
                      bases: Sequence | None = None, progress=None, **fit_options) -> RankingBootstrap:
    """Fit every law to the same ``n`` resampled copies of ``dataset`` and count first places by AIC.

    method 'case' (default) assumes no law's model; 'residual' resamples around the best law's fit;
    'parametric' simulates from the best (unflagged) law's fit with the declared noise.
    laws: names or LawFit objects (distinct labels). tie: AIC difference counted as a tie (default
    ranking.TIE_AIC). bases: the laws' FitResults on the original data, if already made.
    progress(done, n): called after each batch of resamples.
    """
    from ..verdicts.ranking import TIE_AIC

    _check_n(n, seed)
    tie = TIE_AIC if tie is None else tie
    fns = [f if isinstance(f, LawFit) else law_fit(f, solver, **fit_options) for f in laws]
    names = [f.label for f in fns]
    if len(set(names)) != len(names):
        raise ParameterError(f"bootstrap: candidates must differ; got {', '.join(names)}")
    if bases is not None and len(bases) != len(fns):
        raise ParameterError(f"bootstrap: {len(bases)} base fits given for {len(fns)} candidates")
    prepared = [_prepare(f, dataset, "case", b) for f, b in zip(fns, bases or [None] * len(fns))]
    datasets = prepared[0][0]
    models = [None] * len(datasets)
    if method in ("residual", "parametric"):  # resample around the best unflagged fit to the original data
        best = min(range(len(fns)), key=lambda i: (bool(getattr(prepared[i][1], "flags", ())), _aic(prepared[i][1])))
        models = _prepare(fns[best], dataset, method, prepared[best][1])[2]
    elif method not in METHODS:
        raise ParameterError(f"bootstrap: method must be one of {', '.join(METHODS)}, got {method!r}")
    rows = _dispatch(executor, [(p[5], p[3]) for p in prepared], datasets, models, method, seed, n, chunk,
                     progress)
    results = {name: _collect(p[1].law, datasets, method, seed, p[3], p[4], p[1], rows, k)
               for k, (name, p) in enumerate(zip(names, prepared))}
    first = dict.fromkeys(names, 0.0)
    ranked = 0
    for row in rows:
        aics = np.array([cell[1] for cell in row])
        if not np.all(np.isfinite(aics)):
            continue
        ranked += 1
        winners = [names[k] for k in np.nonzero(aics <= aics.min() + tie)[0]]
        for w in winners:
            first[w] += 1.0 / len(winners)
    return RankingBootstrap(laws=tuple(names), datasets=tuple(d.name for d in datasets), first=first,
                            n_ranked=ranked, results=results)


# --- tables for the comparison report ----------------------------------------------------------------
def wilson(k: float, m: int, level: float = 0.95) -> tuple[float, float]:
    """Wilson score interval of a proportion k / m at ``level`` (nan, nan for m = 0)."""
    from statistics import NormalDist

    if not m:
        return math.nan, math.nan
    z = NormalDist().inv_cdf(0.5 + level / 2.0)
    p = k / m
    centre = (p + z * z / (2 * m)) / (1 + z * z / m)
    half = z * math.sqrt(p * (1 - p) / m + z * z / (4 * m * m)) / (1 + z * z / m)
    return (0.0 if k <= 0 else max(0.0, centre - half)), (1.0 if k >= m else min(1.0, centre + half))


def parameter_table(results, level: float = 0.95) -> list[dict]:
    """Rows: law, solver, datasets, parameter, unit, value (original fit), stderr (lmfit),
    boot_median, boot_std, ci_low, ci_high (percentile, ``level``), n_ok, n_failed, method, seed.
    SI units."""
    if isinstance(results, BootstrapResult):
        results = [results]
    elif isinstance(results, RankingBootstrap):
        results = list(results.results.values())
    elif isinstance(results, Mapping):
        results = list(results.values())
    rows = []
    for b in results:
        for name, unit in zip(b.names, b.units):
            col = b._column(name)
            lo, hi = b.interval(name, level)
            p = b.base.params[name]
            rows.append({"law": b.law, "solver": b.base.solver, "datasets": "+".join(b.datasets), "parameter": name,
                         "unit": unit, "shown": p.shown,
                         "value": p.value, "stderr": p.stderr, "boot_median": float(np.median(col)) if col.size else math.nan,
                         "boot_std": b.std(name), "ci_low": lo, "ci_high": hi, "level": level, "n_ok": int(col.size),
                         "n_failed": len(b.failures), "method": b.method, "seed": b.seed})
    return rows


def ranking_table(rb: RankingBootstrap, level: float = 0.95) -> list[dict]:
    """Rows: datasets, candidate (label), law, solver, first_fraction with a Wilson interval at
    ``level``, first_count, n_ranked (replicates where every candidate's refit succeeded), method,
    seed; most often first on top."""
    m = rb.n_ranked
    rows = []
    for law in rb.laws:
        k = rb.first[law]
        p = k / m if m else math.nan
        lo, hi = wilson(k, m, level)
        any_result = rb.results[law]
        rows.append({"datasets": "+".join(rb.datasets), "candidate": law, "law": any_result.law,
                     "solver": any_result.base.solver, "first_fraction": p, "ci_low": lo, "ci_high": hi,
                     "level": level, "first_count": k, "n_ranked": m, "method": any_result.method,
                     "seed": any_result.seed})
    return sorted(rows, key=lambda r: -(r["first_fraction"] if math.isfinite(r["first_fraction"]) else -1))


# --- the comparison's bootstrap ------------------------------------------------------------------------
def bootstrap_fits(fits, n: int, seed: int = 0, executor=None, slow: bool = False, free: Mapping | None = None,
                   progress=None, timeout: float | None = None) -> tuple[list[RankingBootstrap], dict]:
    """Bootstrap the single-dataset fits of a comparison, parametrically: per dataset, ``n`` replicates
    simulated from the best unflagged fit with the noise the likelihood uses (measured or estimated), and every candidate that fitted
    (law [solver]; structurally identical laws once, ``ranking.merge_identical``) refitted to them,
    warm-started from its fit, which is reused as the base. Noise-free reconstructions ('none')
    are skipped with that reason: resampling them would measure the method's determinism. Without ``slow``, only datasets
    whose every fit is one closed-form or series solution per evaluation are bootstrapped: not those
    where a law needs the ODE solver, nor those without a time series (an impact-outcome set
    simulates every impact at each evaluation).
    progress(dataset, done, n): after each batch of resamples, and (n, n) for a dataset left out.
    Returns (one RankingBootstrap per dataset, {dataset: why it was not bootstrapped})."""
    from ..verdicts.ranking import merge_identical

    by_ds: dict = {}
    for f in fits:
        if len(f.datasets) == 1:
            by_ds.setdefault(f.datasets[0], []).append(f)
    out, skipped = [], {}
    for name, group in by_ds.items():
        ok = [f for f in group if f.ok]
        why = _slow(ok, n) if ok else ""
        target = ok[0].per_dataset[0].target if ok else None
        if not ok:
            skipped[name] = "no law could be fitted"
        elif target.derivation or target.dataset.noise_kind == "none":
            skipped[name] = (f"no firmness figure: a noise-free {target.dataset.provenance.kind} series has no noise "
                             "to simulate replicates with")
        elif why and not slow:
            skipped[name] = why
        else:
            from ..fitting.predict import has_scene_quantity

            mine = {k: v for k, v in (free or {}).items() if has_scene_quantity(target.dataset.scene, k)}
            opts = ({"free": mine} if mine else {}) | ({"timeout": timeout} if timeout is not None else {})
            merged = merge_identical(ok)
            fns = [attrs.evolve(law_fit(f.law, f.solver, **opts), name=" = ".join(members) if len(members) > 1 else "")
                   for f, members, _ in merged]
            try:
                out.append(bootstrap_ranking(fns, target.dataset, n=n, seed=seed, method="parametric",
                                             executor=executor, bases=[f for f, _, _ in merged],
                                             progress=progress and (
                                                 lambda done, total, name=name: progress(name, done, total))))
            except FrictionLabError as exc:
                skipped[name] = str(exc)
        if progress and name in skipped:
            progress(name, n, n)
    return out, skipped


def _slow(fits, n: int) -> str:
    """Why refitting ``fits`` (one dataset's) n times is slow, or '' if it is not."""
    ode = [f for f in fits if f.solver.startswith("ode")]
    target = fits[0].per_dataset[0].target
    if ode:
        what = f"{', '.join(f'{f.law} [{f.solver}]' for f in ode)} need{'s' * (len(ode) == 1)} the ODE solver here"
    elif target.t is None:
        kind = target.dataset.kind
        what = (f"{'an' if kind[0] in 'aeiou' else 'a'} {kind} set: each evaluation of a fit simulates every one "
                f"of its {target.y.size} rows")
        ode = fits
    else:
        return ""
    one = len(ode) == 1
    return (f"{what}; {'its fit' if one else 'their fits'} took {sum(f.cpu_time for f in ode):.1f} CPU s on the "
            f"original data, and each of the {n} resamples would refit {'it' if one else 'them'}; add "
            "--bootstrap-all to include it")
