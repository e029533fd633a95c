"""'Bootstrap': first-place shares under parametric resampling and parameter intervals."""
from __future__ import annotations

import math

from ..core.display import fmt, interval_text, param_text
from ..inference.resampling.ranking_bootstrap import parameter_table, ranking_table
from ..inference.verdicts.ranking import TIE_AIC
from .doc import Section
from .summary import first_share
from .text import pct

TITLE = "Bootstrap: how firm are the parameters and the ranking"


def build(ctx) -> Section:
    c = ctx.c
    sec = Section(TITLE)
    n, seed = c.settings.get("bootstrap", 0), c.settings.get("seed", 0)
    if not n:
        sec.p("Not run: this comparison was made with `--bootstrap 0`, so it has no confidence intervals from "
              "resampling; the error bars under Fits are lmfit's standard errors only. Run `frictionlab compare "
              "--bootstrap N` to add them.")
        return sec
    sec.p(f"Each candidate (law [solver]) was refitted to the same {n} **parametric replicates** of its dataset: the "
          "best unflagged fit plus Gaussian noise of the sigma the likelihood uses (measured, or estimated from the data), so the time structure of "
          "a series is never resampled; noise-free reconstructions get no firmness figure. Each refit "
          "starts from the "
          "candidate's best fit on the original data (no grid scan, one Levenberg-Marquardt run). Parameter "
          "intervals are 95% **percentile intervals** (2.5th to 97.5th percentile of the refitted values). "
          "**First place** is the share of resamples in which a candidate has the lowest AIC (candidates within "
          f"ΔAIC ≤ {TIE_AIC} share first place and split the count), with a 95% **Wilson score interval**. "
          f"Seed {seed} (`--seed`), the same for every dataset, so a dataset's numbers do not depend on which "
          "others are compared, nor on the number of worker processes.")
    if c.bootstrap_skipped:
        sec.p("**Not bootstrapped:**")
        sec.items([f"**{d}**: {why.replace('--bootstrap-all', '`--bootstrap-all`')}"
                   for d, why in c.bootstrap_skipped.items()])
    if not c.bootstrap:
        return sec
    _first_places(sec, c)
    _parameters(sec, c)
    return sec


def _first_places(sec: Section, c) -> None:
    rows = []
    for rb in c.bootstrap:
        best = [r for r in c.ranking if r.dataset == rb.datasets[0] and r.rank == 1]
        labels = {r.candidate for r in best}
        table = ranking_table(rb)
        others = [f"{r['candidate']} {pct(r['first_fraction'])} ({pct(r['ci_low'])}–{pct(r['ci_high'])})"
                  for r in table if r["first_count"] > 0 and r["candidate"] not in labels]
        never = [r["candidate"] for r in table if r["first_count"] == 0 and r["candidate"] not in labels]
        rows.append([rb.datasets[0], " = ".join(r.candidate for r in best), first_share(rb, best),
                     "; ".join(others) or "none", ", ".join(never)])
    sec.h3("First place under resampling")
    sec.p("Candidates tied on the original data (the same curve, such as wear and Couette on a given area history) "
          "split each first place between them; their shares are summed here. results.json has each one's share.")
    sec.table(["dataset", "best on the original data", "its first places", "others ever first: share (95% interval)",
               "never first"], rows)


def _parameters(sec: Section, c) -> None:
    sec.h3("Parameter intervals")
    sec.p("Beside each fitted value and its lmfit standard error: the bootstrap median and 95% interval, and the "
          "interval's width relative to ±1.96 standard errors. Near 1 the two agree; well above 1 the standard "
          "error is too optimistic (it assumes the model is right and the residuals are independent noise); well "
          "below 1 the resamples barely move the fit.")
    prow, undetermined = [], {}
    for rb in c.bootstrap:
        for r in parameter_table(rb):
            width = (r["ci_high"] - r["ci_low"]) / (2 * 1.96 * r["stderr"]) if r["stderr"] else math.nan
            prow.append([r["datasets"], f"{r['law']} [{r['solver']}]", r["parameter"],
                         param_text(r["value"], r["stderr"], r["unit"], r.get("shown", "")),
                         param_text(r["boot_median"], None, r["unit"], r.get("shown", "")) if r["n_ok"] else "",
                         interval_text(r["ci_low"], r["ci_high"], r["unit"], r.get("shown", "")), fmt(width, 2),
                         f"{r['n_ok']} of {r['n_ok'] + r['n_failed']}"])
        for b in rb.results.values():
            missing = b.base.identifiability.missing_stderr
            left = [p.name for p in b.base.params.values() if p.vary and p.name not in b.names]
            if left:
                why = "; ".join(dict.fromkeys(missing.get(k, "not determined") for k in left))
                cands, dss = undetermined.setdefault((", ".join(left), why), ({}, {}))
                cands[f"{b.law} [{b.base.solver}]"] = dss[rb.datasets[0]] = None
    sec.table(["dataset", "law [solver]", "parameter", "fit ± standard error", "bootstrap median",
               "95% interval", "width vs ±1.96σ", "refits ok"], prow)
    if undetermined:
        sec.p("Not bootstrapped, because the data do not determine them (the combination that is determined, such "
              "as eta/h, is in the table):")
        sec.items([f"{params} ({', '.join(cands)} on {', '.join(dss)}): {'each ' if ',' in params else ''}{why}"
                   for (params, why), (cands, dss) in undetermined.items()])
