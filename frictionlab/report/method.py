"""'Method', 'Files' and 'Versions': how the numbers were made and what the folder holds."""
from __future__ import annotations

import json

from ..predict import FIT_RTOL
from ..ranking import COLUMNS, TIE_AIC
from .doc import Section
from .results import SCHEMA
from .text import rtol_text


def build(ctx) -> list[Section]:
    c = ctx.c
    method = Section("Method")
    method.items([
        "Fits: lmfit Levenberg-Marquardt on residuals (model − data)/σ, σ the dataset's stated noise; parameters "
        "scaled by their typical size so the optimizer sees order-one numbers; a grid of starts is scored first "
        "and the best few distinct ones are refined; dataset `[fixed]` values are held.",
        "Standard errors: from the covariance scaled by the reduced χ² (lmfit's default), i.e. they assume the "
        "model is right and the noise level is as estimated by the residuals.",
        "Statistics: χ² = Σ((model − data)/σ)², reduced χ² = χ²/(n − k), AIC = n ln(χ²/n) + 2k, "
        "AICc = AIC + 2k(k+1)/(n − k − 1), BIC = n ln(χ²/n) + k ln n (lmfit's convention). k counts the "
        "identifiable directions (rank of the Jacobian): a pair entering only as a ratio counts once, a "
        "parameter without effect not at all.",
        f"Ties: candidates within ΔAIC ≤ {TIE_AIC} share a rank. Akaike weight w = exp(−Δ/2)/Σexp(−Δ/2).",
        "Solvers: 'exact' where the law and scene admit a closed form, else 'ode' (LSODA, rtol "
        f"{rtol_text(FIT_RTOL)}; what another tolerance changes is under 'What solver tolerance does to a fit'); 'series' "
        "(the paper's first-order expansion, eqs 7-11) in addition wherever it is defined.",
        "Bootstrap (`--bootstrap N`, `--seed`): case resampling, every candidate refitted to the same resamples; "
        "95% percentile intervals for parameters, 95% Wilson intervals for first-place shares (see 'Bootstrap').",
        f"Settings: {json.dumps(c.settings)}.",
    ])
    files = Section("Files")
    files.items([
        "`ranking.csv`: " + ", ".join(COLUMNS) + " — per-dataset rows, then group rows (ALL, ALL[kind]); rss and "
        "rmse in the observable's SI unit, named in the unit columns; empty for groups.",
        f"`results.json`: schema `{SCHEMA}` — every fit with parameters, errors, correlations, statistics, "
        "identifiability and notes; the rankings; the equivalence results; dataset provenance; versions. The "
        "schema is documented in `frictionlab/report/results.py`.",
        "`figures/`: the PNG figures of this report; `report.html` embeds them.",
    ])
    versions = Section("Versions")
    versions.table(["component", "version"], [[k, v] for k, v in c.versions.items()])
    return [method, files, versions]
