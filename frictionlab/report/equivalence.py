"""'Equivalence test': can the data tell two laws apart, and are their curves within the margin (``equivalence.py``)?"""
from __future__ import annotations


from ..core.display import fmt
from ..inference.verdicts import rules
from ..inference.equivalence.discrimination import ALPHA, AREA_RATE, WEAR, sentence
from . import figures
from .doc import Section

TITLE = "Equivalence test: different, equivalent within a margin, or cannot tell?"


def _p(e, p: float) -> str:
    return f"{p:.2g} ± {e.mc_error(p):.1g}"


def method_text(replicates: int, margin_text: str, family_text: str) -> str:
    """The rule as applied (``inference.verdicts.rules``), and the decomposition's caveat."""
    return (rules.equivalence(replicates, margin_text, family_text) + " " + sentence(rules.qualitative()) + " The "
            "decomposition F ≈ λu0(1 − b)A + (λu0b/(φA0)) A dA/dt rests on the truncated slip (eq 7 of Arakawa 2017), "
            "so it is shown for the series fit only; that paper prints the second factor as φ/A0, dimensionally it "
            "is 1/(φA0).")


def margin_rule(c) -> str:
    """'1 × the noise σ of each dataset (the default)' or what was asked for."""
    m = c.options.margin if c.options is not None else None
    if m is None or m.default:
        return rules.margin_default()
    if m.relative:
        return (f"{m.multiple:g} × the noise σ of each dataset (stated precisions for a reconstruction's stated "
                "numbers), as asked with --margin")
    return f"{m.quantity}, as asked with --margin"


def family_rule(c) -> str:
    """The family the report's p-values are adjusted in, and how many hypotheses it holds."""
    stored = next((e.family for e in c.equivalence if e.tested), "")  # as adjusted (a page of a group: the report's)
    n = int(stored.split()[3]) if stored.startswith("Holm over the ") else 2 * sum(1 for e in c.equivalence if e.tested)
    family = (c.options.family if c.options is not None else "report")
    if family == "group":
        return (f"Holm's step-down within each dataset group (the per-group rule, asked for with --family group): "
                f"each group's chance of any wrong 'different' or 'equivalent within δ' is at most α = {ALPHA:g}, "
                "not the report's")
    return (f"Holm's step-down over all {n} hypotheses of this report (two per tested pair: 'neither law is rejected' "
            f"and 'the curves differ by δ or more'): the chance that any 'different' or 'equivalent within δ' in "
            f"this report is wrong is at most α = {ALPHA:g}; adjusted p-values are printed (--family group keeps the "
            "rate per dataset group instead)")


def build(ctx) -> Section:
    c = ctx.c
    sec = Section(TITLE)
    sec.p(method_text(c.settings.get("replicates", 0), margin_rule(c), family_rule(c)))
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
                         f"{e.status}: {e.reason}"] + [""] * 7)
            continue
        q = e.qualitative or {}
        if not e.tested:
            rows.append([e.dataset, f"{e.law_a} [{e.solver_a}]", f"{e.law_b} [{e.solver_b}]", e.verdict, "no test",
                         "", "", "", e.quantity(e.rms), "", _qual(q)])
            continue
        rows.append([e.dataset, f"{e.law_a} [{e.solver_a}]", f"{e.law_b} [{e.solver_b}]", e.verdict,
                     fmt(e.t_obs, 4), _p(e, e.p_a), _p(e, e.p_b), f"{e.p:.2g} / {e.p_adjusted:.2g}",
                     e.quantity(e.rms), f"{e.quantity(e.upper)} vs δ = {e.quantity(e.margin)} "
                                        f"(p {e.p_within:.2g} / {e.p_within_adjusted:.2g})", _qual(q)])
    sec.table(["dataset", "law A", "law B", "verdict", "T = χ²A − χ²B", "p under A", "p under B",
               "two-sided p / adjusted", "distance (RMS)", f"upper {1 - ALPHA:.0%} bound vs δ (p / adjusted)",
               "qualitatively"], rows)
    sec.items([f"**{e.dataset}: {e.label} — {e.verdict}**: {e.explanation}" for e in c.equivalence if e.ok])


def _qual(q: dict) -> str:
    out = q.get("verdict", "") + (f": {q['differs']}" if q.get("differs") else "")
    peak = q.get("peak_time") or {}
    if peak.get("differs"):
        out += f"; peak times {peak['shift'] * 1e6:.0f} µs apart (quantitative)"
    return out


def _figures(sec: Section, c) -> None:
    for d in c.fitted_datasets:
        tested = [e for e in c.equivalence if e.dataset == d.name and e.tested]
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
