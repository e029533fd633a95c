"""'Prediction across conditions': does one parameter set serve every dataset of a group (``transfer.py``)?"""
from __future__ import annotations

from ..core.display import fmt
from ..inference.equivalence.transfer import ALPHA
from .doc import Section

TITLE = "Prediction across conditions"


def build(ctx) -> Section | None:
    c = ctx.c
    if not c.transfer:
        return None
    sec = Section(TITLE)
    sec.p("A law is a material statement: one parameter set should serve every member of a dataset group. "
          "Transfer: the law parameters fitted on one member predict each other member without refitting (scene "
          "quantities and [fixed] values stay the target's own); the error is the RMS in noise sigmas (predictive "
          "χ² and log-likelihood in results.json). Shared against separate: one global fit for the whole group "
          "against separate fits, LR = χ²shared − χ²separate with its chi-square p-value for the extra parameters "
          f"(one set serves when p ≥ {ALPHA:g}), and ΔAIC = AIC shared − AIC separate (negative: one set is preferred).")
    for tr in c.transfer:
        sec.p(f"**{tr.group}** ({', '.join(tr.datasets)}): {tr.answer()}.")
        if tr.status != "ok":
            continue
        rows = []
        for r in tr.ranking():
            preds = [p for p in tr.predictions if p.candidate == r["candidate"]]
            sh = next((s for s in tr.shared if s.candidate == r["candidate"]), None)
            rows.append([f"#{r['rank']}", r["candidate"], fmt(r["rms_sigma"], 3),
                         "; ".join(f"{p.source} → {p.target}: {p.rms_sigma:.3g}" for p in preds),
                         "" if sh is None or sh.status != "ok" else
                         f"LR {fmt(sh.lr, 4)} (dk {sh.dk}), p {sh.p_value:.2g}, ΔAIC {sh.delta_aic:.1f}",
                         "" if sh is None else ("yes" if sh.serves else "no" if sh.serves is False else sh.reason),
                         "" if sh is None else "; ".join(f"{k} {fmt(v, 4)}" for k, v in sh.shared.items())])
        sec.table(["rank", "law [solver]", "RMS error [σ]", "per direction [σ]", "shared vs separate",
                   "one parameter set serves", "shared values [SI]"], rows)
    return sec
