"""'Ranking': the heat map, the group sums, and per dataset every candidate's statistics."""
from __future__ import annotations

import math

from .. import figures
from ..display import fmt, unit
from ..ranking import TIE_AIC
from .doc import Section
from .text import fixed

TITLE = "Ranking"


def candidate_table(rows, observable: str) -> tuple[list[str], list[list]]:
    uname, uf = unit(observable)
    headers = ["rank", "law [solver]", "n", "k", f"RMSE [{uname}]", "reduced χ²", "AIC", "AICc", "BIC", "ΔAIC",
               "Akaike weight", "status"]
    out = []
    for r in rows:
        status = r.status + (f" (with {', '.join(r.tied_with)})" if r.tied_with else "") + \
            (f": {r.reason}" if r.reason else "")
        out.append([r.rank or "–", r.candidate, r.n_points or "", r.n_params if r.rank else "",
                    fmt(r.rmse * uf) if math.isfinite(r.rmse) else "", fmt(r.redchi), fmt(r.aic), fmt(r.aicc),
                    fmt(r.bic), fixed(r.delta_aic, 2), fixed(r.akaike_weight, 3), status])
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
          "effect of the approximation is visible. Weights are Akaike weights within each dataset.")
    ranking = list(c.ranking)
    sec.fig("ranking.png", "Rank and ΔAIC of every law [solver] on every dataset (grey: not fitted).",
            lambda: figures.ranking_figure(ranking))
    sec.h3("Over groups of datasets")
    sec.p("Sums of the per-dataset AIC (independent fits, so log-likelihoods add). 'exact' and 'ode' solve the "
          "same equations and count as one candidate; a candidate that could not be fitted to every dataset of a "
          "group is 'incomplete' there.")
    sec.table(*group_table(list(c.groups)))
    for d in c.fitted_datasets:
        sec.h3(d.name)
        sec.table(*candidate_table([r for r in c.ranking if r.dataset == d.name], d.observable))
    return sec
