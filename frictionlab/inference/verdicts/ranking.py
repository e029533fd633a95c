"""Rank fitted (law, solver) candidates per dataset and over groups of datasets.

Statistics per candidate: RSS and RMSE (observable's SI unit), reduced chi-square, the
likelihood used (known or profiled sigma, see ``fitting``), AIC, AICc, BIC, delta-AIC to the
best candidate, Akaike weight w_i = exp(-delta_i / 2) / sum_j exp(-delta_j / 2) over the candidates that pass
their fit tests (``weight_among``: a weight compares descriptions that hold; a candidate that fails gets
none, and where none fits there are no weights), the goodness
of fit (``goodness.py``: chi-square p, runs-test p, lag-1 autocorrelation, and whether it fits)
and the plausibility flags (``plausibility.py``).

Rules, stated once:
* Structural identity: laws whose closed-form family is the same (``law.form()`` of one class,
  each law spanning the whole family, e.g. wear and couette: F = k A u with k = lam = eta/h) are
  ONE candidate, labelled 'wear = couette', carrying every member's parameterization.
* Order: by AIC, except that a flagged candidate (``plausibility.py``) ranks after every unflagged one
  not rejected by its fit tests (a physically implausible fit never ranks ahead of a plausible one
  that fits; its row says why). The flag alone never puts it after a candidate that fails its fit
  tests: against those, AIC decides. Competition rank (1, 1, 3): only
  candidates within ``TIE_AIC`` of each other share a rank (the same curve).
* Near-ties: candidates within delta-AIC < ``NEAR_TIE`` (2) of each other are 'indistinguishable
  by these data' (Burnham and Anderson 2002: Delta < 2 means substantial support for both).

Over a group of datasets (each group of two or more members its datasets declare, ``answers.group_of``; no
group of every dataset is formed: datasets of different experiments, materials or kinds are not summed unless
their files say they belong together) -2 ln L adds over the candidate's independent
per-dataset fits, k adds, and AIC, AICc and BIC are computed from the group's n and k; the
goodness p-values are Bonferroni-adjusted over the members. A candidate is ranked there only if
it fitted every dataset of the group. The 'series' solver is its own candidate; 'exact' and
'ode' solve the same equations, so they count as one ('full') for the group totals.
"""
from __future__ import annotations

import math
from collections import defaultdict

import attrs
import numpy as np

from ..fitting.model import FTOL
from ..fitting.fit import FitResult

#: Candidates whose AIC differ by at most this much share a rank (the same fitted curve).
TIE_AIC = 0.01
#: Candidates closer than this in AIC are indistinguishable by the data.
NEAR_TIE = 2.0

COLUMNS = ("dataset", "law", "solver", "n_points", "n_params", "rss", "rmse", "redchi", "likelihood", "aic", "aicc",
           "bic", "delta_aic", "akaike_weight", "weight_among", "rank", "status", "chi2_p", "runs_p", "lag1", "fits",
           "flags", "at_bounds", "reason")  # at_bounds: 'k at upper bound 1e+06 1/m'; reason: why a fit failed or was skipped


@attrs.frozen
class RankRow:
    """One row of the ranking (``ranking.csv``, `Comparison.to_dataframe`).

    Attributes
    ----------
    dataset : str
        The dataset, or a group (``ALL``, ``ALL[kind]``).
    law, solver, candidate : str
        The law, its solver, and the candidate they form (``"wear [exact]"``).
    rank : int
        Its rank by AIC; candidates within ``TIE_AIC`` share one.
    rss, rmse : float
        Residual sum of squares and root mean square in the observable's SI unit (nan for groups).
    aic, bic, delta_aic, akaike_weight : float
        Information criteria, the distance to the best, and the Akaike weight among the candidates that fit.
    fits : bool
        Whether it passes its goodness-of-fit tests.
    """

    dataset: str
    law: str
    solver: str
    n_points: int = 0
    n_params: int = 0
    rss: float = math.nan
    rmse: float = math.nan
    redchi: float = math.nan
    aic: float = math.nan
    aicc: float = math.nan
    bic: float = math.nan
    delta_aic: float = math.nan
    akaike_weight: float = math.nan
    rank: int | None = None
    status: str = "ok"  # ok | tied | indistinguishable | failed | skipped | incomplete
    reason: str = ""
    tied_with: tuple[str, ...] = ()  # candidates within NEAR_TIE (tied: within TIE_AIC)
    likelihood: str = ""  # 'known' | 'estimated' | 'mixed' | 'none' (fitting.Stats.likelihood)
    neg2loglik: float = math.nan
    k_lik: int = 0  # parameters counted by the criteria 
    chi2_p: float = math.nan
    runs_p: float = math.nan
    lag1: float = math.nan
    fits: bool | None = None  # passes the goodness-of-fit rule (goodness.FITS_LEVEL)
    goodness: object = None  # goodness.Goodness
    flags: tuple[str, ...] = ()  # plausibility flags: such a candidate ranks after the unflagged ones that fit
    members: tuple[str, ...] = ()  # laws of one closed-form family merged into this candidate
    parameterizations: str = ""  # each member's parameters, e.g. "wear: lam = 2e4 Pa s/m; couette: eta/h = ..."
    at_bounds: tuple[str, ...] = ()  # parameters at a bound of their range ('k at upper bound 1e+06 1/m'): not identifiable
    weight_among: tuple[str, ...] = ()  # the candidates the Akaike weight compares (those that pass their fit tests)

    @property
    def candidate(self) -> str:
        """'law [solver]', the name the ranking shows."""
        return f"{self.law} [{self.solver}]"

    def as_dict(self) -> dict:
        """The row as plain values.

        Returns
        -------
        dict
            Column name to value, as ``ranking.csv`` and ``results.json`` record them.
        """
        out = {c: getattr(self, c) for c in COLUMNS}
        out["flags"] = "; ".join(self.flags)
        out["at_bounds"] = "; ".join(self.at_bounds)
        out["weight_among"] = "; ".join(self.weight_among)
        return out

    @property
    def weight_text(self) -> str:
        """'Akaike weight 0.72 among coulomb [exact], area-rate [exact] (the candidates that fit)', or why there is
        none."""
        return weight_text(self.akaike_weight, self.weight_among, self.fits)


def family(solver: str) -> str:
    """'series' for the paper's truncated expansion, 'full' for exact or numerical solutions."""
    return "series" if solver == "series" else "full"


RANKED = ("ok", "tied", "indistinguishable")


def _rank(rows: list[RankRow], tie: float) -> list[RankRow]:
    ok = [r for r in rows if r.status in RANKED and math.isfinite(r.aic)]
    if not ok:
        return rows
    best = min(r.aic for r in ok)
    ranked = {id(r) for r in ok}
    fitting = [r for r in ok if r.fits is not False]  # weights compare candidates that pass their fit tests
    among = tuple(r.candidate for r in fitting)
    low = min((r.aic for r in fitting), default=math.nan)
    weights = {id(r): math.exp(-(r.aic - low) / 2) for r in fitting}
    total = sum(weights.values())

    eff = _placing_aic(ok)

    def ahead(o, r):  # o ranks strictly ahead of r: lower placing AIC beyond the tie, then unflagged first
        d = eff[id(o)] - eff[id(r)]
        return d < -tie or (abs(d) <= tie and not o.flags and bool(r.flags))

    out = []
    for r in rows:
        if id(r) not in ranked:
            out.append(r)
            continue
        rank = 1 + sum(1 for o in ok if ahead(o, r))
        same = [o for o in ok if o is not r and abs(eff[id(o)] - eff[id(r)]) <= tie and bool(o.flags) == bool(r.flags)]
        near = tuple(o.candidate for o in ok if o is not r and abs(o.aic - r.aic) < NEAR_TIE)
        status = "tied" if same else ("indistinguishable" if near else "ok")
        weight = weights[id(r)] / total if id(r) in weights else math.nan
        out.append(attrs.evolve(r, delta_aic=r.aic - best, akaike_weight=weight, rank=rank, status=status,
                                tied_with=near, weight_among=among if id(r) in weights else ()))
    return sorted(out, key=lambda r: (r.rank is None, r.rank or 0, r.law, r.solver))


def weight_text(weight: float, among, fits) -> str:
    """An Akaike weight with what it compares, or why a candidate has none."""
    if fits is False:
        return "no Akaike weight: it fails its fit tests (weights compare candidates that fit)"
    if not math.isfinite(weight) or not among:
        return "no Akaike weight"
    if len(among) == 1:
        return "Akaike weight 1 by construction: the only candidate that fits"
    return f"Akaike weight {weight:.2f} among {', '.join(among)} (the candidates that fit)"


def _placing_aic(ok: list[RankRow]) -> dict[int, float]:
    """The AIC each candidate is placed by: its own, but a flagged one's at least the largest AIC of the
    unflagged candidates not rejected by their fit tests, so that it ranks after each of them and, by the
    flag alone, never after one that fails its fit tests."""
    plain = [r.aic for r in ok if not r.flags and r.fits is not False]
    floor = max(plain) if plain else -math.inf
    return {id(r): max(r.aic, floor) if r.flags else r.aic for r in ok}


def fit_row(f: FitResult) -> RankRow:
    """The unranked row of a single-dataset fit."""
    name = f.datasets[0] if len(f.datasets) == 1 else "+".join(f.datasets)
    if not f.ok:
        return RankRow(name, f.law, f.solver, status=f.status, reason=f.reason)
    s, g = f.stats, f.goodness
    return RankRow(name, f.law, f.solver, s.n_points, s.n_params, s.rss, s.rmse, s.redchi, s.aic, s.aicc, s.bic,
                   likelihood=s.likelihood, neg2loglik=s.neg2loglik, k_lik=s.k_lik,
                   chi2_p=g.chi2_p if g else math.nan, runs_p=g.runs_p if g else math.nan,
                   lag1=g.lag1 if g else math.nan, fits=g.fits if g else None, goodness=g, flags=tuple(f.flags),
                   members=(f.law,), at_bounds=bound_labels(f))


def bound_labels(f: FitResult) -> tuple[str, ...]:
    """'k at upper bound 1e+06 1/m' per parameter of ``f`` at a bound (``identifiability.at_bounds``)."""
    from ..diagnostics.identifiability import at_bounds

    return tuple(f"{h.name} at {h.side} bound {h.bound:.6g}{' ' + h.unit if h.unit else ''}" for h in at_bounds(f))


def family_key(f: FitResult):
    """(form class, solver) if the law spans its whole closed-form family on this fit, else None."""
    from ...physics.registry import get_law

    if not f.ok or len(f.per_dataset) != 1:
        return None
    try:
        form = get_law(f.law).form(f.per_dataset[0].params)
    except Exception:  # a law whose form cannot be evaluated has no family to share
        return None
    if form is None or len(attrs.fields(type(form))) != f.stats.n_params:
        return None
    return type(form), f.solver


def _parameterization(f: FitResult) -> str:
    shown = [f"{p.name} = {p.value:.4g} {p.unit}".rstrip() for k, p in f.params.items() if k in f.determined]
    held = [f"{p.name} = {p.value:.4g} {p.unit} held".rstrip() for p in f.params.values() if not p.vary and p.fixed_by
            and p.kind == "law"]
    return f"{f.law}: " + ", ".join(shown + held)


def merge_identical(fits: list[FitResult]) -> list[tuple[FitResult, tuple[str, ...], str]]:
    """Single-dataset fits with structurally identical laws merged: (representative, member laws, their
    parameterizations and the shared form), in order of first appearance. The representative is the simplest
    member (fewest parameters) of those at the lowest AIC within the fits' relative tolerance (``fitmodel.FTOL``
    of chi-square): the members reach one minimum, and which of them lands a round-off lower decides nothing."""
    from ...physics.registry import get_law

    groups: dict = {}
    order = []
    for f in fits:
        key = family_key(f)
        key = (f.datasets, key) if key else (f.datasets, id(f))
        if key not in groups:
            groups[key] = []
            order.append(key)
        groups[key].append(f)
    out = []
    for key in order:
        members = groups[key]
        if len(members) == 1:
            out.append((members[0], (members[0].law,), ""))
            continue
        members = sorted(members, key=lambda f: (len(get_law(f.law).params), f.law))  # 'wear = couette': simplest first
        score = {id(f): f.stats.aic if math.isfinite(f.stats.aic) else f.stats.chisqr for f in members}
        low = min(score.values())  # one minimum, reached by each within the fits' own tolerance: the simplest stands
        best = next((f for f in members if score[id(f)] <= low + FTOL * max(1.0, f.stats.chisqr)), members[0])
        form_cls = key[1][0]
        what = (form_cls.__doc__ or form_cls.__name__).split(".")[0]
        text = (f"one closed-form family ({what}): " + "; ".join(_parameterization(f) for f in members))
        out.append((best, tuple(f.law for f in members), text))
    return out


def rank_fits(fits: list[FitResult], tie: float = TIE_AIC) -> list[RankRow]:
    """Per-dataset ranking of single-dataset fits, grouped by dataset in order of appearance; laws of
    one closed-form family are one candidate (``merge_identical``)."""
    groups: dict[str, list[RankRow]] = defaultdict(list)
    for f, members, text in merge_identical(list(fits)):
        row = fit_row(f)
        if len(members) > 1:
            row = attrs.evolve(row, law=" = ".join(members), members=members, parameterizations=text)
        groups[row.dataset].append(row)
    out = []
    for rows in groups.values():
        out += _rank(rows, tie)
    return out


def rank_groups(rows: list[RankRow], kinds: dict[str, str] | None = None, tie: float = TIE_AIC,
                named: dict[str, str] | None = None) -> list[RankRow]:
    """Aggregate per-dataset rows into each declared group of two or more datasets (``named``: dataset -> group
    label; ``kinds`` is not used: datasets are pooled only where their files say they belong together), and rank
    them.

    A group contains the datasets on which at least one candidate fitted; a candidate is ranked
    there only if it fitted all of them ('incomplete' otherwise, with the missing datasets named).
    """
    by_name = defaultdict(list)
    for d in sorted({r.dataset for r in rows}):
        if named and d in named:
            by_name[named[d]].append(d)
    groups = {g: v for g, v in by_name.items() if len(v) > 1}
    out = []
    for gname, members in groups.items():
        fitted = [d for d in members if any(r.status in RANKED and r.dataset == d for r in rows)]
        cands = defaultdict(dict)
        for r in rows:
            if r.dataset in fitted:
                cands[(r.law, family(r.solver))][r.dataset] = r
        grow = []
        for (law, fam), per in cands.items():
            good = [per[d] for d in fitted if d in per and per[d].status in RANKED]
            solver = "+".join(sorted({r.solver for r in per.values()}))
            if len(good) < len(fitted):
                missing = [d for d in fitted if d not in per or per[d].status not in RANKED]
                grow.append(RankRow(gname, law, solver, status="incomplete",
                                    reason=f"no fit on {len(missing)} of {len(fitted)} datasets: {', '.join(missing)}"))
                continue
            grow.append(_group_row(gname, law, solver, good))
        out += _rank(grow, tie)
    return out


def _group_row(gname: str, law: str, solver: str, good: list[RankRow]) -> RankRow:
    """A candidate over a group of separately fitted members: -2 ln L, k, AIC, AICc and BIC are sums over the
    members (each member's AICc and BIC with its own n and k)."""
    from ..diagnostics.goodness import combine

    n = sum(r.n_points for r in good)
    k = sum(r.n_params for r in good)
    kl = sum(r.k_lik for r in good)
    chi = sum(r.redchi * (r.n_points - r.n_params) for r in good)
    ll = sum(r.neg2loglik for r in good)
    aic = ll + 2 * kl
    aicc = sum(r.aicc for r in good)
    bic = sum(r.bic for r in good)
    kinds = {r.likelihood for r in good}
    g = combine([r.goodness for r in good]) if all(r.goodness is not None for r in good) else None
    flags = tuple(f"{r.dataset}: {f}" for r in good for f in r.flags)
    bounds = tuple(f"{r.dataset}: {b}" for r in good for b in r.at_bounds)
    return RankRow(gname, law, solver, n, k, math.nan, math.nan, chi / (n - k) if n > k else math.inf, aic, aicc,
                   bic, likelihood=kinds.pop() if len(kinds) == 1 else "mixed", neg2loglik=ll,
                   k_lik=kl, chi2_p=g.chi2_p if g else math.nan, runs_p=g.runs_p if g else math.nan,
                   lag1=g.lag1 if g else math.nan, fits=g.fits if g else None, goodness=g, flags=flags,
                   members=good[0].members, at_bounds=bounds, parameterizations=" | ".join(
                       f"{r.dataset}: {r.parameterizations}" for r in good if r.parameterizations))


def to_csv(rows: list[RankRow]) -> str:
    """ranking.csv text: COLUMNS, full precision, empty cells for missing numbers."""

    def cell(v):
        if v is None:
            return ""
        if isinstance(v, float):
            return "" if not math.isfinite(v) else f"{v:.10g}"
        text = str(v)
        return '"' + text.replace('"', '""') + '"' if ("," in text or '"' in text) else text

    lines = [",".join(COLUMNS)] + [",".join(cell(d[c]) for c in COLUMNS) for d in (r.as_dict() for r in rows)]
    return "\n".join(lines) + "\n"


def best_candidates(rows: list[RankRow], dataset: str) -> list[RankRow]:
    return [r for r in rows if r.dataset == dataset and r.rank == 1]


def weights_table(rows: list[RankRow]) -> dict[str, dict[str, float]]:
    """dataset -> candidate -> Akaike weight (ranked rows only)."""
    out: dict[str, dict[str, float]] = defaultdict(dict)
    for r in rows:
        if r.rank is not None and np.isfinite(r.akaike_weight):
            out[r.dataset][r.candidate] = r.akaike_weight
    return dict(out)
