"""'Equivalence test': can the data tell two laws apart (the discrimination test of ``equivalence.py``)?"""
from __future__ import annotations

from ..core.display import fmt
from ..inference.equivalence import ALPHA, AREA_RATE, BATCH, CRITICAL, POWER, WEAR
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
          "T = χ²(A) − χ²(B) at the σ the likelihood uses (measured, estimated from the data, or a "
          "reconstruction's stated precision; −2 ln of the likelihood ratio), each law tested with T centred at "
          "its location under that law's fit (the other law refitted to its best curve: Cox's statistic). Replicate "
          "datasets are simulated from each law's best fit with that same σ (an estimated σ re-drawn per replicate "
          "from its chi-square law), both laws refitted to each and T re-centred, sequentially in batches of "
          f"{BATCH} (at most {R} per law): sampling stops once every p-value's 99% Monte-Carlo interval lies "
          f"above {ALPHA / 2:g}, or one lies below it, or the data lie beyond all of a law's replicates with a "
          "conservative exponential-tail p far below it. One two-sided rule at "
          f"α = {ALPHA:g} (p = 2 min(p_A, p_B)): **not equivalent** if T rejects a law (the text says which, and never "
          "calls data consistent with a law that fails its own fit tests); **equivalent** if T rejects neither "
          f"and the two null distributions overlap (each law's replicates reject the other less than {POWER:.0%} of "
          "the time); **cannot tell at this noise** if T rejects neither although the test has power. A group's "
          "verdict uses Holm's step-down across its members. The noise threshold, both directions: the σ at which "
          f"a fit of one law to the other's noise-free best curve misses it by χ² {CRITICAL:g} (about 50% power), "
          "beside the RMS difference of the two curves. 'Qualitatively' (the paper's word): do the two fitted "
          "curves share the data's features (a rise, a peak inside the record and its time within the sampling "
          "interval, a fall before the end, one sign of the friction force)? The paper's decomposition "
          "F ≈ λu0(1 − b)A + (λu0b/(φA0)) A dA/dt rests on its truncated slip (eq 7), so it is shown for the "
          "series fit only; the paper prints the second factor as φ/A0, dimensionally it is 1/(φA0).")
    if not c.equivalence:
        sec.p("Not run: it needs both laws of a pair in the comparison (or --no-equivalence was given).")
        return sec
    _table(sec, c)
    _figures(sec, c)
    return sec


def _table(sec: Section, c) -> None:
    rows = []
    for e in c.equivalence:
        if not e.ok:
            rows.append([e.dataset, f"{e.law_a} [{e.solver_a}]", f"{e.law_b} [{e.solver_b}]",
                         f"{e.status}: {e.reason}"] + [""] * 6)
            continue
        q = e.qualitative or {}
        rows.append([e.dataset, f"{e.law_a} [{e.solver_a}]", f"{e.law_b} [{e.solver_b}]", e.verdict,
                     fmt(e.t_obs, 4), _p(e, e.p_a), _p(e, e.p_b), f"{e.p:.2g}",
                     f"{e.power_a:.0%} / {e.power_b:.0%}", q.get("verdict", "") +
                     (f": {q['differs']}" if q.get("differs") else "")])
    sec.table(["dataset", "law A", "law B", "verdict", "T = χ²A − χ²B", "p under A", "p under B", "two-sided p",
               "power (reject A | B / reject B | A)", "qualitatively"], rows)
    sec.items([f"**{e.dataset}: {e.label} — {e.verdict}**: {e.explanation}" for e in c.equivalence if e.ok])


def _figures(sec: Section, c) -> None:
    for d in c.fitted_datasets:
        tested = [e for e in c.equivalence if e.dataset == d.name and e.ok]
        if tested:
            sec.fig(f"discrimination-{d.name}.png",
                    f"{d.name}: T under each law's fit (histograms) and on the data (line): where the histograms "
                    "overlap, data of this noise cannot tell the laws apart. Each law's p is taken on T centred at "
                    "that law's own fit (the text gives both).",
                    lambda d=d, tested=tested: figures.discrimination_figure(d.name, tested))
    for e in c.equivalence:
        if e.decomposition is not None:
            dec = e.decomposition
            fa = c.fit_for(e.dataset, AREA_RATE)
            fitted = (f" against fitted μ = {fmt(fa.value('mu'), 3)}, η′ = {fmt(fa.value('eta_prime'), 3)} N s/m²"
                      if fa is not None and fa.ok else "")
            sec.p(f"{e.dataset}: the paper's decomposition of the wear series fit (b = {dec.b:.3g}) implies "
                  f"μ = {dec.mu:.3g}, η′ = {dec.eta_prime:.4g} N s/m²{fitted} (projection R² = {dec.r2:.2f}).")
    for d in c.fitted_datasets:  # the forces alone are in the fits section's force figure: drawn once, not here
        mine = [e for e in c.equivalence if e.dataset == d.name and e.ok and (e.law_a, e.law_b) == (WEAR, AREA_RATE)
                and e.decomposition is not None]
        if not mine:
            continue
        fa = c.fit_for(d.name, AREA_RATE, mine[0].solver_b)
        fws = [c.fit_for(d.name, WEAR, e.solver_a) for e in mine]
        sec.fig(f"equivalence-{d.name}.png", f"{d.name}: the paper's decomposition of the wear series fit and its "
                "projection onto μN + μη′dA/dt, over the friction force of both fits (every fit's force: "
                f"force-{d.name}.png).",
                lambda d=d, fws=fws, fa=fa, mine=mine: figures.equivalence_figure(d, fws, fa,
                                                                                  [e.decomposition for e in mine]))
