"""Rank fitted (law, solver) candidates per dataset and over groups of datasets.

Statistics per candidate: RSS and RMSE (observable's SI unit), reduced chi-square, AIC, AICc,
BIC (see ``fitting.Stats``), delta-AIC to the best candidate, Akaike weight
w_i = exp(-delta_i / 2) / sum_j exp(-delta_j / 2), and a competition rank (1, 1, 3) in which
candidates within ``TIE_AIC`` of each other share a rank: their fits are the same curve
(e.g. wear and couette, which share the form F = k A u).

Over a group of datasets ('ALL', and 'ALL[kind]' when kinds differ) a candidate's AIC, AICc
and BIC are sums of its independent per-dataset fits (log-likelihoods add); it is ranked only
if it fitted every dataset of the group. The 'series' solver is its own candidate; 'exact'
and 'ode' solve the same equations, so they count as one ('full') for the group totals.
"""
from __future__ import annotations

import math
from collections import defaultdict

import attrs
import numpy as np

from .fitting import FitResult

#: Candidates whose AIC differ by at most this much share a rank (the same fitted curve).
TIE_AIC = 0.01

COLUMNS = ("dataset", "law", "solver", "n_points", "n_params", "rss", "rmse", "redchi", "aic", "aicc", "bic",
           "delta_aic", "akaike_weight", "rank", "status", "reason")  # reason: why a fit failed or was skipped


@attrs.frozen
class RankRow:
    """One row of ranking.csv. rss and rmse are in the observable's SI unit (nan for groups)."""

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
    status: str = "ok"  # ok | tied | failed | skipped | incomplete
    reason: str = ""
    tied_with: tuple[str, ...] = ()

    @property
    def candidate(self) -> str:
        return f"{self.law} [{self.solver}]"

    def as_dict(self) -> dict:
        return {c: getattr(self, c) for c in COLUMNS}


def family(solver: str) -> str:
    """'series' for the paper's truncated expansion, 'full' for exact or numerical solutions."""
    return "series" if solver == "series" else "full"


def _rank(rows: list[RankRow], tie: float) -> list[RankRow]:
    ok = [r for r in rows if r.status in ("ok", "tied") and math.isfinite(r.aic)]
    if not ok:
        return rows
    best = min(r.aic for r in ok)
    weights = {id(r): math.exp(-(r.aic - best) / 2) for r in ok}
    total = sum(weights.values())
    out = []
    for r in rows:
        if id(r) not in weights:
            out.append(r)
            continue
        rank = 1 + sum(1 for o in ok if o.aic < r.aic - tie)
        tied = tuple(o.candidate for o in ok if o is not r and abs(o.aic - r.aic) <= tie)
        out.append(attrs.evolve(r, delta_aic=r.aic - best, akaike_weight=weights[id(r)] / total, rank=rank,
                                status="tied" if tied else "ok", tied_with=tied))
    return sorted(out, key=lambda r: (r.rank is None, r.rank or 0, r.law, r.solver))


def fit_row(f: FitResult) -> RankRow:
    """The unranked row of a single-dataset fit."""
    name = f.datasets[0] if len(f.datasets) == 1 else "+".join(f.datasets)
    if not f.ok:
        return RankRow(name, f.law, f.solver, status=f.status, reason=f.reason)
    s = f.stats
    return RankRow(name, f.law, f.solver, s.n_points, s.n_params, s.rss, s.rmse, s.redchi, s.aic, s.aicc, s.bic)


def rank_fits(fits: list[FitResult], tie: float = TIE_AIC) -> list[RankRow]:
    """Per-dataset ranking of single-dataset fits, grouped by dataset in order of appearance."""
    groups: dict[str, list[RankRow]] = defaultdict(list)
    for f in fits:
        row = fit_row(f)
        groups[row.dataset].append(row)
    out = []
    for rows in groups.values():
        out += _rank(rows, tie)
    return out


def rank_groups(rows: list[RankRow], kinds: dict[str, str] | None = None, tie: float = TIE_AIC) -> list[RankRow]:
    """Aggregate per-dataset rows into 'ALL' (and 'ALL[kind]' when kinds differ) and rank them.

    A group contains the datasets on which at least one candidate fitted; a candidate is ranked
    there only if it fitted all of them ('incomplete' otherwise, with the missing datasets named).
    """
    kinds = kinds or {}
    groups = {"ALL": sorted({r.dataset for r in rows})}
    by_kind = defaultdict(list)
    for d in groups["ALL"]:
        by_kind[kinds.get(d, "?")].append(d)
    if len(by_kind) > 1:
        groups.update({f"ALL[{k}]": v for k, v in sorted(by_kind.items()) if len(v) > 1})
    out = []
    for gname, members in groups.items():
        fitted = [d for d in members if any(r.status in ("ok", "tied") and r.dataset == d for r in rows)]
        cands = defaultdict(dict)
        for r in rows:
            if r.dataset in fitted:
                cands[(r.law, family(r.solver))][r.dataset] = r
        grow = []
        for (law, fam), per in cands.items():
            good = [per[d] for d in fitted if d in per and per[d].status in ("ok", "tied")]
            solver = "+".join(sorted({r.solver for r in per.values()}))
            if len(good) < len(fitted):
                missing = [d for d in fitted if d not in per or per[d].status not in ("ok", "tied")]
                grow.append(RankRow(gname, law, solver, status="incomplete",
                                    reason=f"no fit on {len(missing)} of {len(fitted)} datasets: {', '.join(missing)}"))
                continue
            n = sum(r.n_points for r in good)
            k = sum(r.n_params for r in good)
            chi = sum(r.redchi * (r.n_points - r.n_params) for r in good)
            grow.append(RankRow(gname, law, solver, n, k, math.nan, math.nan, chi / (n - k) if n > k else math.inf,
                                sum(r.aic for r in good), sum(r.aicc for r in good), sum(r.bic for r in good)))
        out += _rank(grow, tie)
    return out


def to_csv(rows: list[RankRow]) -> str:
    """ranking.csv text: COLUMNS, full precision, empty cells for missing numbers."""

    def cell(v):
        if v is None:
            return ""
        if isinstance(v, float):
            return "" if not math.isfinite(v) else f"{v:.10g}"
        text = str(v)
        return f'"{text}"' if ("," in text or '"' in text) else text

    lines = [",".join(COLUMNS)] + [",".join(cell(getattr(r, c)) for c in COLUMNS) for r in rows]
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
