"""'Method', 'Files' and 'Versions': how the numbers were made and what the folder holds."""
from __future__ import annotations

import json

from ..inference.fitting.predict import FIT_RTOL
from ..inference.verdicts import rules
from ..inference.verdicts.ranking import COLUMNS
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
        "Likelihood and standard errors follow each dataset's `[noise] kind`: known σ (measured): −2 ln L = χ² + "
        "Σ ln(2πσ²), standard errors from the covariance unscaled; estimated σ (the default, when none is measured): "
        "σ from the data alone by Gasser-Sroka-Jennen-Steinmetz differences or the spread of replicates, the same "
        "for every law, used the same way, its degrees of freedom carried into the F test of fit; none (a "
        "noise-free reconstruction): no likelihood. No guessed σ is used. "
        "A fit to ω derived from θ by a smoother has correlated points: no likelihood, criteria or error bars.",
        "Statistics: χ² = Σ((model − data)/σ)², reduced χ² = χ²/(n − k), AIC = −2 ln L + 2k, "
        "AICc = AIC + 2k(k+1)/(n − k − 1), BIC = −2 ln L + k ln n. k counts the "
        "identifiable directions (rank of the Jacobian): a pair entering only as a ratio counts once, a "
        "parameter without effect not at all. Groups add −2 ln L and k and use the group's n.",
        f"Goodness of fit: {rules.goodness()}.",
        f"Plausibility: {rules.plausibility()}.",
        f"Ties and weights: {rules.ties()}. Laws of one closed-form family (law.form()) are one candidate, e.g. "
        f"wear = couette; {rules.weights()}.",
        f"Identifiability: {rules.bounds()}; {rules.correlation()}.",
        "Solvers: 'exact' where the law and scene admit a closed form, else 'ode' (LSODA, rtol "
        f"{rtol_text(FIT_RTOL)}; what another tolerance changes is under 'What solver tolerance does to a fit'); 'series' "
        "(the first-order expansion of Arakawa 2017, eqs 7-11) in addition wherever it is defined.",
        "Bootstrap (`--bootstrap N`, `--seed`): parametric (the best unflagged fit plus Gaussian noise of the σ the "
        "likelihood uses, measured or estimated from the data; none for a noise-free reconstruction), every "
        "candidate refitted to the same replicates; "
        "95% percentile intervals for parameters, 95% Wilson intervals for first-place shares (see 'Bootstrap').",
        f"Settings: {json.dumps(c.settings)}.",
    ])
    files = Section("Files")
    files.items([
        "`ranking.csv`: " + ", ".join(COLUMNS) + " — per-dataset rows, then the rows of each declared group of two or more datasets; rss and "
        "rmse in the observable's SI unit, named in the unit columns; empty for groups.",
        f"`results.json`: schema `{SCHEMA}` — every fit with parameters, errors, correlations, statistics, "
        "identifiability and notes; the rankings; the equivalence results; dataset provenance; versions. The "
        "schema is documented in `frictionlab/report/results.py`.",
        "`figures/`: the PNG figures of this report; `report.html` embeds them.",
    ])
    versions = Section("Versions")
    versions.table(["component", "version"], [[k, v] for k, v in c.versions.items()])
    return [method, files, versions]
