"""'Ranking': the heat map, the group sums, and per dataset every candidate's statistics."""
from __future__ import annotations

import math

from .. import figures
from ..display import fmt, unit
from ..ranking import TIE_AIC
from .doc import Section
from .text import fixed

TITLE = "Ranking"


def curve_labels(c, dataset: str) -> dict[tuple[str, str], str]:
    """(law, solver) -> 'couette = wear' for the fits on ``dataset`` that are one curve (figures.same_curve)."""
    out = {}
    for f, laws in figures.distinct_curves(c.fits_on(dataset)):
        for law in laws:
            out[(law, f.solver)] = " = ".join(laws)
    return out


def law_aliases(c) -> dict[str, str]:
    """law -> shared label for laws whose fits are one curve on every dataset and solver where both were fitted."""
    together: dict[frozenset, bool] = {}
    for d in c.fitted_datasets:
        labels = curve_labels(c, d.name)
        fitted = {(f.law, f.solver) for f in c.fits_on(d.name) if f.ok}
        for a, sa in fitted:
            for b, sb in fitted:
                if a < b and sa == sb:
                    key = frozenset((a, b))
                    together[key] = together.get(key, True) and labels.get((a, sa)) == labels.get((b, sb))
    alias: dict[str, str] = {}
    for key, same in together.items():
        if same:
            merged = sorted(set(alias.get(min(key), min(key)).split(" = ")) | set(key))
            for law in merged:
                alias[law] = " = ".join(merged)
    return alias


def candidate_table(rows, observable: str, labels: dict | None = None) -> tuple[list[str], list[list]]:
    """One row per candidate; candidates whose fits are one curve (``labels``) share one row, their Akaike
    weights summed."""
    uname, uf = unit(observable)
    headers = ["rank", "law [solver]", "n", "k", f"RMSE [{uname}]", "reduced χ²", "AIC", "AICc", "BIC", "ΔAIC",
               "Akaike weight", "status"]
    labels = labels or {}
    merged: dict[str, list] = {}
    for r in rows:
        merged.setdefault(f"{labels.get((r.law, r.solver), r.law)} [{r.solver}]" if r.rank else r.candidate,
                          []).append(r)
    out = []
    for name, rs in merged.items():
        r = rs[0]
        same = len(rs) > 1
        tied = [t for t in r.tied_with if t not in {x.candidate for x in rs}]
        status = ("same curve" if same and r.status == "tied" and not tied else r.status) \
            + (f" (with {', '.join(tied)})" if tied else "") + (f": {r.reason}" if r.reason else "")
        weight = sum(x.akaike_weight for x in rs) if r.rank else r.akaike_weight
        out.append([r.rank or "–", name, r.n_points or "", r.n_params if r.rank else "",
                    fmt(r.rmse * uf) if math.isfinite(r.rmse) else "", fmt(r.redchi), fmt(r.aic), fmt(r.aicc),
                    fmt(r.bic), fixed(r.delta_aic, 2), fixed(weight, 3), status])
    return headers, out


def group_table(rows) -> tuple[list[str], list[list]]:
    headers = ["group", "rank", "law [solver]", "n", "k", "reduced χ²", "ΣAIC", "ΣAICc", "ΣBIC", "ΔAIC",
               "Akaike weight", "status"]
    out = [[r.dataset, r.rank or "–", r.candidate, r.n_points or "", r.n_params if r.rank else "", fmt(r.redchi),
            fmt(r.aic), fmt(r.aicc), fmt(r.bic), fixed(r.delta_aic, 2), fixed(r.akaike_weight, 3),
            r.status + (f": {r.reason}" if r.reason else "")] for r in rows]
    return headers, out

def build(ctx) -> Section:
    c = ctx.c
    sec = Section(TITLE)
    sec.p(f"Each law is fitted separately to each dataset and ranked by AIC; candidates within ΔAIC ≤ {TIE_AIC} "
          "share a rank (their best fits are the same curve). The solver is part of the candidate: where the paper's "
          "truncated series applies it is ranked next to the exact (or numerical) solution of the same law, so the "
          "effect of the approximation is visible. Weights are Akaike weights within each dataset. Laws whose best "
          "fits are the same curve (wear and Couette share the form F = k A u) are one row, their weights summed.")
    ranking, alias = list(c.ranking), law_aliases(c)
    sec.fig("ranking.png", "Rank and ΔAIC of every law [solver] on every dataset (grey: not fitted); laws whose "
            "fits are the same curve on every dataset share a row.", lambda: figures.ranking_figure(ranking, alias))
    sec.h3("Over groups of datasets")
    sec.p("Sums of the per-dataset AIC (independent fits, so log-likelihoods add). 'exact' and 'ode' solve the "
          "same equations and count as one candidate; a candidate that could not be fitted to every dataset of a "
          "group is 'incomplete' there.")
    sec.table(*group_table(list(c.groups)))
    for d in c.fitted_datasets:
        sec.h3(d.name)
        sec.table(*candidate_table([r for r in c.ranking if r.dataset == d.name], d.observable,
                                   curve_labels(c, d.name)))
    return sec
