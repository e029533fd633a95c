"""Refits for the equivalence test: each law refitted, warm-started, to a curve or a replicate dataset."""
from __future__ import annotations

import math
import zlib

import numpy as np

from ...core.errors import FrictionLabError
from ...physics.registry import get_law
from ..fitting.fit import FitResult, Target, fit


def refit_options(f: FitResult) -> dict:
    """fit() keywords that repeat ``f``'s setup, warm-started at its best values. Of a pair that enters
    only through its ratio (eta/h) the second is held: the chi-square is the same, the search shorter."""
    held = {pair[1] for pair in (f.identifiability.ratio_only if f.identifiability else ())}
    initial = {p.key: p.value for p in f.params.values() if p.kind == "law" and p.vary and p.name not in held}
    fixed = {p.key: p.value for p in f.params.values()
             if p.kind == "law" and (p.fixed_by == "held by the caller" or (p.vary and p.name in held))}
    free = {p.key: (p.lower, p.upper, p.value) for p in f.params.values() if p.kind == "scene" and p.vary}
    out = {"solver": f.per_dataset[0].solver, "initial": initial, "fixed": fixed, "free": free}
    own = getattr(f.per_dataset[0], "refit", None)  # a velocity-step fit: its trend and stiffness, as fitted
    return out | own if own else out


def noise_of(f: FitResult):
    """A velocity-step fit's noise model per dataset, to hold in a refit to its noise-free curve (None: none)."""
    states = tuple(getattr(d, "noise_state", None) for d in f.per_dataset)
    return states if any(st is not None for st in states) else None


def profiled(fit_a: FitResult, fit_b: FitResult) -> bool:
    """Whether either fit estimates its noise model with the law (the data's AR(p), its level profiled)."""
    return any((getattr(d, "noise_state", None) or {}).get("kind") == "arp" for f in (fit_a, fit_b)
               for d in f.per_dataset)


def t_stat(fit_a: FitResult, fit_b: FitResult) -> float:
    """T = -2 ln(L_A / L_B): chi2_A - chi2_B at the noise the likelihood uses; where a fit estimates its noise
    model with the law (``profiled``), the difference of the profiled -2 ln L (chi-square is then n)."""
    if profiled(fit_a, fit_b):
        return float(fit_a.stats.neg2loglik - fit_b.stats.neg2loglik)
    return float(fit_a.stats.chisqr - fit_b.stats.chisqr)


def batch_problem(law, opts: dict, target: Target):
    """The batched refit problem (``batchfit.Problem``) of ``law`` on ``target`` with ``opts`` (``refit_options``:
    solver, initial, fixed, free), or None where no batched route serves: then ``refit`` one at a time."""
    from ..fitting import batch as batchfit
    from ..fitting.model import _law_slots
    from ..fitting.fit import law_values

    law = get_law(law)
    if opts.get("free"):
        return None
    try:
        fixed = law_values(law, opts.get("fixed") or {}, "fit: fixed")
        initial = law_values(law, opts.get("initial") or {}, "fit: initial")
        slots = _law_slots(law, [target], fixed, set(), initial)
    except FrictionLabError:
        return None
    return batchfit.served(batchfit.Problem(law, target, opts.get("solver"), slots))


def refit(law: str, opts: dict, target: Target, scan: int = 0, n_starts: int = 1) -> FitResult:
    """``law`` refitted to ``target`` with ``opts`` (``refit_options``; a velocity-step fit's trend and stiffness
    as fitted, and 'noise': a noise model to hold)."""
    extra = {k: opts[k] for k in ("trend", "stiffness", "noise") if opts.get(k) is not None}
    return fit(law, target, solver=opts["solver"], initial=opts["initial"], fixed=opts["fixed"] or None,
               free=opts["free"] or None, scan=scan, n_starts=n_starts, checks=False, errors=False,
               timeout=opts.get("timeout"), **extra)


def with_y(target: Target, y: np.ndarray, what: str) -> Target:
    """``target`` with values y (a replicate or a fitted curve, ``what``). A measured friction series of a
    spring-slider keeps being one, so that its refit is the velocity-step fit of the data (trend, stiffness, step
    time, noise); elsewhere y is marked as ``what`` (its refit's likelihood is then the caller's to state)."""
    velocity_steps = (target.dataset.kind == "spring-slider" and target.observable == "mu" and not target.derivation
                      and target.t is not None)
    return Target(target.dataset, target.observable, y, target.sigma, "" if velocity_steps else what)


def cross_chi2(own: FitResult, other: FitResult, timeout: float | None = None) -> float:
    """``own``'s law refitted to ``other``'s noise-free best curve: the chi-square it is left with
    at the declared noise (nan if the refit fails, or takes longer than ``timeout`` seconds)."""
    d = other.per_dataset[0]
    tg = with_y(d.target, d.model.copy(), f"best fit of {other.law}")
    r = refit(own.law, refit_options(own) | {"timeout": timeout, "noise": noise_of(other)}, tg, scan=25, n_starts=2)
    return float(r.stats.chisqr) if r.ok else math.nan


def centring(law: str, opts: dict, start: FitResult | None, target: Target, curve: np.ndarray, noise=None) -> float:
    """``law`` refitted to the noise-free ``curve`` (on ``target``'s points and sigma), warm-started at
    ``start``'s values (``opts``' when None): the chi-square it is left with, the plug-in for the
    location of T under the law that made ``curve`` (nan if the refit fails). noise: the noise model of the fit
    that made ``curve`` (``noise_of``), held in the refit."""
    return centring_fit(law, opts, start, target, curve, noise)[0]


def centring_fit(law: str, opts: dict, start: FitResult | None, target: Target,
                 curve: np.ndarray, noise=None) -> tuple[float, np.ndarray | None]:
    """``centring``'s chi-square and the refitted curve itself (None if the refit fails)."""
    if noise is not None:
        opts = opts | {"noise": noise}
    if start is not None:
        now = {p.key: p.value for p in start.params.values()}
        opts = opts | {"initial": {k: now.get(k, v) for k, v in opts["initial"].items()},
                       "free": {k: (lo, hi, now.get(k, v)) for k, (lo, hi, v) in opts["free"].items()}}
    try:
        r = refit(law, opts, with_y(target, curve, "a fitted curve"))
    except FrictionLabError:
        return math.nan, None
    return (float(r.stats.chisqr), r.per_dataset[0].model) if r.ok else (math.nan, None)


def distance(target: Target, a: np.ndarray, b: np.ndarray) -> float:
    """RMS difference of two curves on ``target``'s points, in the observable's SI unit (stated numbers, whose
    units differ: in stated precisions)."""
    d = (np.asarray(a, dtype=float) - np.asarray(b, dtype=float))
    if target.observable == "stated":
        d = d / np.asarray(target.sigma, dtype=float)
    return float(np.sqrt(np.mean(d * d)))


#: Columns of a replicate row of ``replicate_chunk``.
ROW = ("t_a", "s_a", "d_a", "t_b", "s_b", "d_b", "sigma_ratio")


def replicate_chunk(law_a, opts_a, law_b, opts_b, target, model_a, model_b, seeds,
                    df: float = math.inf) -> list[tuple[float, ...]]:
    """Per seed a row ``ROW``: (T, S_A, D) on a replicate of A's fit, (T, S_B, D) on one of B's, and the
    replicate's sigma estimate over the data's (1 for a measured sigma); nan where a refit failed.
    S_A = T + (B refitted to A's refitted curve), S_B = T - (A refitted to B's refitted curve): T centred
    at its location under the replicate's own fit (``equivalence``, module docstring); D the RMS distance of
    the two refitted curves (``distance``). With an estimated sigma of ``df`` degrees of freedom each
    replicate's chi-squares are at its own estimate sigma^2 chi2_df / df. The refits of every seed are made
    together where a batched route serves (``batchfit``), else one at a time. Runs in a worker."""
    from ..noise.record import noise_drawer

    noise = noise_drawer(target.dataset, target.y, model_a, target.sigma)  # Gaussian, AR(1) or AR(p) as declared
    eps, scale = [], []
    for ss in seeds:
        rng = np.random.default_rng(ss)
        eps.append(noise(rng))
        scale.append(df / rng.chisquare(df) if math.isfinite(df) else 1.0)
    laws = ((law_a, opts_a), (law_b, opts_b))
    got = _batched_rows(laws, target, model_a, model_b, eps)
    rows = []
    for i, sc in enumerate(scale):
        ra = got[0][i] or _null_row(laws, target, "a", model_a + eps[i])
        rb = got[1][i] or _null_row(laws, target, "b", model_b + eps[i])
        rows.append((sc * ra[0], sc * ra[1], ra[2], sc * rb[0], sc * rb[1], rb[2], 1.0 / math.sqrt(sc)))
    return rows


def _batched_rows(laws, target, model_a, model_b, eps: list) -> tuple[list, list]:
    """(T, S, D) per replicate under null A and under null B (``replicate_chunk``, before the sigma draw's scale),
    each replicate's refits made in batches (``batchfit``: both laws on the replicates of both nulls, then each
    null's centring refit); None for a replicate the batches did not serve, every one where none serves."""
    from ..fitting import batch as batchfit

    (law_a, opts_a), (law_b, opts_b) = laws
    r = len(eps)
    none = ([None] * r, [None] * r)
    pa, pb = batch_problem(law_a, opts_a, target), batch_problem(law_b, opts_b, target)
    if not r or pa is None or pb is None:
        return none
    E = np.asarray(eps)
    Y = np.concatenate([model_a + E, model_b + E])  # the replicates of null A, then those of null B
    ra, rb = batchfit.refit_many(pa, Y), batchfit.refit_many(pb, Y)
    if ra is None or rb is None:
        return none
    head, tail = slice(0, r), slice(r, 2 * r)
    # under A: B refitted to A's refitted curve, from B's refit; under B: A to B's curve, from A's refit
    cb = batchfit.refit_many(pb, ra.models[head], starts={k: v[head] for k, v in rb.values.items()})
    ca = batchfit.refit_many(pa, rb.models[tail], starts={k: v[tail] for k, v in ra.values.items()})
    t = ra.chisqr - rb.chisqr
    out = []
    for part, centre, sign in ((head, cb, 1.0), (tail, ca, -1.0)):
        ok = ra.ok[part] & rb.ok[part] & (centre.ok if centre is not None else False)
        out.append([[float(t[part][i]), float(t[part][i] + sign * centre.chisqr[i]),
                     distance(target, ra.models[part][i], rb.models[part][i])] if ok[i] else None for i in range(r)])
    return out[0], out[1]


def _null_row(laws, target, null: str, y: np.ndarray) -> list[float]:
    """(T, S, D) of one replicate y under ``null``, its refits made one at a time (``replicate_chunk``)."""
    (law_a, opts_a), (law_b, opts_b) = laws
    tg = with_y(target, y, "parametric bootstrap replicate")
    try:
        ra, rb = refit(law_a, opts_a, tg), refit(law_b, opts_b, tg)
    except FrictionLabError:
        return [math.nan] * 3
    if not (ra.ok and rb.ok):
        return [math.nan] * 3
    t = t_stat(ra, rb)
    if null == "a":
        s = t + centring(law_b, opts_b, rb, target, ra.per_dataset[0].model, noise_of(ra))
    else:
        s = t - centring(law_a, opts_a, ra, target, rb.per_dataset[0].model, noise_of(rb))
    return [t, s, distance(target, ra.per_dataset[0].model, rb.per_dataset[0].model)]


def one_family(fit_a: FitResult, fit_b: FitResult) -> bool:
    """Whether the two laws are one model on this dataset: each spans the whole of one closed-form family
    with one solver (``ranking.family_key``; wear and Couette, F = k A u). Then each law's refit to any
    replicate is the other's (the same least-squares problem in k), so T* = 0 on every replicate and
    the test needs no refits."""
    from ..verdicts.ranking import family_key

    key = family_key(fit_a)
    return key is not None and key == family_key(fit_b) and refit_options(fit_a)["free"].keys() == \
        refit_options(fit_b)["free"].keys()


def seed_sequence(seed: int, key: str) -> np.random.SeedSequence:
    """The replicates' seed sequence for ``seed`` and a dataset/pair ``key``; successive ``spawn`` calls
    continue it, so sequential batches draw the same replicates as one long run."""
    return np.random.SeedSequence([int(seed), zlib.crc32(key.encode())])
