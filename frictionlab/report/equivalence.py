"""'Equivalence test': can the data tell two laws apart (the discrimination test of ``equivalence.py``)?"""
from __future__ import annotations

from ..core.display import fmt
from ..inference.equivalence import ALPHA, AREA_RATE, CRITICAL, POWER, WEAR
from . import figures
from .doc import Section

TITLE = "Equivalence test: can the data tell two laws apart?"


def _p(e, p: float) -> str:
    return f"{p:.2g} ± {e.mc_error(p):.1g}"


def build(ctx) -> Section:
    c = ctx.c
    sec = Section(TITLE)
    R = c.settings.get("replicates", 0)
    sec.p("The paper claims that the wear law λAu is 'qualitatively equivalent' to the empirical μN + μη′dA/dt. "
          "Per dataset, each pair of laws is put to a Cox-type discrimination test: the statistic is "
          "T = χ²(A) − χ²(B) at the dataset's declared noise (−2 ln of the likelihood ratio); "
          f"{R} replicate datasets are simulated from each law's best fit with that noise, both laws are refitted "
          "to each, and the observed T is compared with its distribution under A (large T rejects A) and under B "
          f"(small T rejects B) at level {ALPHA:g}, with the Monte-Carlo error of each p-value. Verdict: **not "
          "equivalent** if T rejects a law (the text says which); **equivalent** if T is consistent with both and "
          f"the two null distributions overlap (each law's replicates reject the other less than {POWER:.0%} of the "
          "time): data of this noise cannot tell them apart; **cannot tell at this noise** if T is consistent with "
          "both although the test has power. T compares the two laws only: whether either fits is the "
          "goodness-of-fit question. The noise threshold: each law refitted to the other's noise-free best curve "
          "leaves a χ² that scales as 1/σ²; the laws differ by more than the noise below the σ at which the larger "
          f"reaches {CRITICAL:g} (χ², one degree of freedom, 95%). The paper's decomposition "
          "F ≈ λu0(1 − b)A + (λu0b/(φA0)) A dA/dt rests on its truncated slip (eq 7), so it is shown for the "
          "series fit only; the paper prints the second factor as φ/A0, dimensionally it is 1/(φA0).")
    if not c.equivalence:
        sec.p("Not run: it needs both laws of a pair in the comparison (or --no-equivalence was given).")
        return sec
    rows = []
    for e in c.equivalence:
        if not e.ok:
            rows.append([e.dataset, f"{e.law_a} [{e.solver_a}]", f"{e.law_b} [{e.solver_b}]",
                         f"{e.status}: {e.reason}"] + [""] * 5)
            continue
        rows.append([e.dataset, f"{e.law_a} [{e.solver_a}]", f"{e.law_b} [{e.solver_b}]", e.verdict,
                     fmt(e.t_obs, 4), _p(e, e.p_a), _p(e, e.p_b), f"{e.power_a:.0%} / {e.power_b:.0%}",
                     e.threshold_text()])
    sec.table(["dataset", "law A", "law B", "verdict", "T = χ²A − χ²B", "p under A", "p under B",
               "power (reject A | B / reject B | A)", "noise threshold"], rows)
    sec.items([f"**{e.dataset}: {e.label} — {e.verdict}**: {e.explanation}" for e in c.equivalence if e.ok])
    for d in c.fitted_datasets:
        tested = [e for e in c.equivalence if e.dataset == d.name and e.ok]
        if tested:
            sec.fig(f"discrimination-{d.name}.png",
                    f"{d.name}: T under each law's fit (histograms) and on the data (line); a law is rejected when "
                    "the line lies in the far tail of its histogram.",
                    lambda d=d, tested=tested: figures.discrimination_figure(d.name, tested))
    for e in c.equivalence:
        if e.decomposition is not None:
            dec = e.decomposition
            fa = c.fit_for(e.dataset, AREA_RATE)
            fitted = (f" against fitted μ = {fmt(fa.value('mu'), 3)}, η′ = {fmt(fa.value('eta_prime'), 3)} N s/m²"
                      if fa is not None and fa.ok else "")
            sec.p(f"{e.dataset}: the paper's decomposition of the wear series fit (b = {dec.b:.3g}) implies "
                  f"μ = {dec.mu:.3g}, η′ = {dec.eta_prime:.4g} N s/m²{fitted} (projection R² = {dec.r2:.2f}).")
    for d in c.fitted_datasets:
        mine = [e for e in c.equivalence if e.dataset == d.name and e.ok and (e.law_a, e.law_b) == (WEAR, AREA_RATE)]
        if not mine:
            continue
        fa = c.fit_for(d.name, AREA_RATE, mine[0].solver_b)
        fws = [c.fit_for(d.name, WEAR, e.solver_a) for e in mine]
        sec.fig(f"equivalence-{d.name}.png", f"{d.name}: friction force of the wear and area-rate fits"
                + (", and the paper's decomposition of the series fit with its projection onto μN + μη′dA/dt."
                   if any(e.decomposition for e in mine) else "."),
                lambda d=d, fws=fws, fa=fa, mine=mine: figures.equivalence_figure(d, fws, fa,
                                                                                  [e.decomposition for e in mine]))
    return sec
