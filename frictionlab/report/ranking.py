"""'Ranking': the heat map, the group sums, and per dataset every candidate's statistics."""
from __future__ import annotations

import math

from ..core.display import OBSERVABLE_UNITS, fmt, unit
from ..inference.verdicts import rules
from ..inference.equivalence.discrimination import sentence
from . import figures
from .doc import Section
from .text import fixed

TITLE = "Ranking"


def curve_labels(c, dataset: str) -> dict[tuple[str, str], str]:
    """(law, solver) -> 'wear = couette' for the fits on ``dataset`` that are one curve (figures.same_curve)."""
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
            merged = figures.simplest_first(set(alias.get(min(key), min(key)).split(" = ")) | set(key))
            for law in merged:
                alias[law] = " = ".join(merged)
    return alias


def candidate_table(rows, observable: str, labels: dict | None = None,
                    display: tuple[str, float] | None = None) -> tuple[list[str], list[list]]:
    """One row per candidate; candidates whose fits are one curve (``labels``) share one row, their Akaike
    weights summed, the first's rank and status ('same curve' when only they are near) and every member's
    flags (another member's marked as its own: e.g. a flagged area-rate whose eta' has no effect, on the
    row of an unflagged Coulomb). display: (unit, factor from SI) of the RMSE, default the observable's display unit."""
    uname, uf = display or unit(observable)
    headers = ["rank", "law [solver]", "n", "k", f"RMSE [{uname}]", "reduced χ²", "AIC", "AICc", "BIC", "ΔAIC",
               "Akaike weight", "fits? (χ² p, runs p)", "status"]
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
        status = ("same curve" if same and r.status in ("tied", "indistinguishable") and not tied else r.status) \
            + (f" (with {', '.join(tied)})" if tied else "") + (f": {r.reason}" if r.reason else "")
        others = "".join(f"; FLAG ({x.law} only): {f}" for x in rs[1:] for f in x.flags if f not in r.flags)
        finite = [x.akaike_weight for x in rs if math.isfinite(x.akaike_weight)]
        weight = (sum(finite) if finite else math.nan) if r.rank else r.akaike_weight
        out.append([r.rank or "–", name, r.n_points or "", r.n_params if r.rank else "",
                    fmt(r.rmse * uf) if math.isfinite(r.rmse) else "", fmt(r.redchi), fmt(r.aic), fmt(r.aicc),
                    fmt(r.bic), fixed(r.delta_aic, 2), _weight_cell(weight, r), _fits_cell(r), status + _flags(r) + others])
    return headers, out


def _weight_cell(weight: float, r) -> str:
    """The Akaike weight, or why there is none (it compares the candidates that fit)."""
    if math.isfinite(weight):
        return fixed(weight, 3)
    return "— (fails its fit tests)" if r.fits is False else ("—" if r.rank else "")


def _fits_cell(r) -> str:
    """'yes (0.57, 0.22)' / 'no (–, 4e-10)': the goodness-of-fit rule's verdict and its p-values."""
    if r.fits is None:
        return ""
    p = lambda x: "–" if not math.isfinite(x) else f"{x:.2g}"  # noqa: E731
    return f"{'yes' if r.fits else 'no'} ({p(r.chi2_p)}, {p(r.runs_p)}; σ {r.likelihood})"


def _flags(r, limit: int | None = None) -> str:
    """'; FLAG: ...' per plausibility flag; with ``limit``, the first ``limit`` and how many more (a group's
    flags are its members', each in full in that dataset's table)."""
    shown = r.flags if limit is None else r.flags[:limit]
    more = len(r.flags) - len(shown)
    head = "; FLAG (ranked after every unflagged candidate that fits): " if r.flags and r.rank else "; FLAG: "
    return "".join((head if i == 0 else "; FLAG: ") + f for i, f in enumerate(shown)) + (f"; {more} more flag{'s' * (more > 1)}: see each dataset's table"
                                                     if more else "")


def group_table(rows) -> tuple[list[str], list[list]]:
    headers = ["group", "rank", "law [solver]", "n", "k", "reduced χ²", "AIC", "AICc", "BIC", "ΔAIC",
               "Akaike weight", "fits? (χ² p, runs p)", "status"]
    out = [[r.dataset, r.rank or "–", r.candidate, r.n_points or "", r.n_params if r.rank else "", fmt(r.redchi),
            fmt(r.aic), fmt(r.aicc), fmt(r.bic), fixed(r.delta_aic, 2), _weight_cell(r.akaike_weight, r), _fits_cell(r),
            r.status + (f": {r.reason}" if r.reason else "") + _flags(r, limit=1)] for r in rows]
    return headers, out

#: Datasets the ranking heat map draws at most (a column each, about 1.25 inches): past them the tables hold the rest.
MAX_COLUMNS = 30


def build(ctx) -> Section:
    c = ctx.c
    sec = Section(TITLE)
    sec.p("Each law is fitted separately to each dataset and ranked by AIC, unflagged candidates first (a fit "
          "flagged as physically implausible ranks after them, its flag in the status); laws of one closed-form "
          f"family are one candidate (wear = couette); {rules.ties()}. Goodness of fit: {rules.goodness()}. "
          f"{sentence(rules.weights())} The solver is part of the candidate: where the truncated series applies it "
          "is ranked next to the exact (or numerical) solution of the same law, so the effect of the approximation "
          "is visible. Laws whose best fits are the same curve (wear and Couette share the form F = k A u) are one "
          "row, their weights summed.")
    ranking, alias = list(c.ranking), law_aliases(c)
    names = list(dict.fromkeys(r.dataset for r in ranking))
    if len(names) > 1:  # across datasets (of one, the table below says it all; none fitted: nothing to draw)
        drawn = [r for r in ranking if r.dataset in set(names[:MAX_COLUMNS])]
        sec.fig("ranking.png", "Rank and ΔAIC of every law [solver] on every dataset (grey: not fitted); laws whose "
                "fits are the same curve on every dataset share a row."
                + (f" The first {MAX_COLUMNS} of {len(names)} datasets; the tables below and ranking.csv hold every "
                   "one." if len(names) > MAX_COLUMNS else ""), lambda: figures.ranking_figure(drawn, alias))
    sec.h3("Over groups of datasets")
    sec.p("−2 ln L and k add over the per-dataset fits (independent, so log-likelihoods add); AIC, AICc and BIC "
          "use the group's n and k; goodness p-values are Bonferroni-adjusted over the members. 'exact' and 'ode' solve the "
          "same equations and count as one candidate; a candidate that could not be fitted to every dataset of a "
          "group is 'incomplete' there.")
    sec.table(*group_table(list(c.groups)))
    for d in c.fitted_datasets:
        sec.h3(d.name)
        lik = next((f.stats for f in c.fits_on(d.name) if f.ok), None)
        if lik is not None:
            sec.p(f"Likelihood: σ {lik.likelihood}. {lik.likelihood_reason[0].upper()}{lik.likelihood_reason[1:]}.")
        shown = unit(d.observable) if d.observable in OBSERVABLE_UNITS else figures.column_unit(d, d.observable)
        sec.table(*candidate_table([r for r in c.ranking if r.dataset == d.name], d.observable,
                                   curve_labels(c, d.name), (shown[0] or "-", shown[1])))
        merged = [f"{r.candidate}: {r.parameterizations}" for r in c.ranking
                  if r.dataset == d.name and r.parameterizations]
        if merged:
            sec.items(merged)
    return sec
