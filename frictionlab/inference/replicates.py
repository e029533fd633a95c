"""Refits for the equivalence test: each law refitted, warm-started, to a curve or a replicate dataset."""
from __future__ import annotations

import math
import zlib

import numpy as np

from ..core.errors import FrictionLabError
from .fitting import FitResult, Target, fit


def refit_options(f: FitResult) -> dict:
    """fit() keywords that repeat ``f``'s setup, warm-started at its best values. Of a pair that enters
    only through its ratio (eta/h) the second is held: the chi-square is the same, the search shorter."""
    held = {pair[1] for pair in (f.identifiability.ratio_only if f.identifiability else ())}
    initial = {p.key: p.value for p in f.params.values() if p.kind == "law" and p.vary and p.name not in held}
    fixed = {p.key: p.value for p in f.params.values()
             if p.kind == "law" and (p.fixed_by == "held by the caller" or (p.vary and p.name in held))}
    free = {p.key: (p.lower, p.upper, p.value) for p in f.params.values() if p.kind == "scene" and p.vary}
    return {"solver": f.per_dataset[0].solver, "initial": initial, "fixed": fixed, "free": free}


def refit(law: str, opts: dict, target: Target, scan: int = 0, n_starts: int = 1) -> FitResult:
    return fit(law, target, solver=opts["solver"], initial=opts["initial"], fixed=opts["fixed"] or None,
               free=opts["free"] or None, scan=scan, n_starts=n_starts, checks=False, errors=False,
               timeout=opts.get("timeout"))


def with_y(target: Target, y: np.ndarray, what: str) -> Target:
    return Target(target.dataset, target.observable, y, target.sigma, what)


def cross_chi2(own: FitResult, other: FitResult, timeout: float | None = None) -> float:
    """``own``'s law refitted to ``other``'s noise-free best curve: the chi-square it is left with
    at the declared noise (nan if the refit fails, or takes longer than ``timeout`` seconds)."""
    d = other.per_dataset[0]
    tg = with_y(d.target, d.model.copy(), f"best fit of {other.law}")
    r = refit(own.law, refit_options(own) | {"timeout": timeout}, tg, scan=25, n_starts=2)
    return float(r.stats.chisqr) if r.ok else math.nan


def replicate_chunk(law_a, opts_a, law_b, opts_b, target, model_a, model_b, seeds) -> list[tuple[float, float]]:
    """(T under A, T under B) per seed; nan where a refit failed. Runs in a worker."""
    out = []
    for ss in seeds:
        eps = np.random.default_rng(ss).standard_normal(target.y.size) * target.sigma
        row = []
        for model in (model_a, model_b):
            tg = with_y(target, model + eps, "parametric bootstrap replicate")
            try:
                ra, rb = refit(law_a, opts_a, tg), refit(law_b, opts_b, tg)
                row.append(ra.stats.chisqr - rb.stats.chisqr if ra.ok and rb.ok else math.nan)
            except FrictionLabError:
                row.append(math.nan)
        out.append(tuple(row))
    return out


def one_family(fit_a: FitResult, fit_b: FitResult) -> bool:
    """Whether the two laws are one model on this dataset: each spans the whole of one closed-form family
    with one solver (``ranking.family_key``; wear and Couette, F = k A u). Then each law's refit to any
    replicate is the other's (the same least-squares problem in k), so T* = 0 on every replicate and
    the test needs no refits."""
    from .ranking import family_key

    key = family_key(fit_a)
    return key is not None and key == family_key(fit_b) and refit_options(fit_a)["free"].keys() == \
        refit_options(fit_b)["free"].keys()


def seed_sequence(seed: int, key: str) -> np.random.SeedSequence:
    """The replicates' seed sequence for ``seed`` and a dataset/pair ``key``; successive ``spawn`` calls
    continue it, so sequential batches draw the same replicates as one long run."""
    return np.random.SeedSequence([int(seed), zlib.crc32(key.encode())])
