"""The verdict layer: one ``answers.Answer`` per dataset group, decided from the ranking.

``make_answers(datasets, fits, ranking, groups)`` reads the candidates already ranked (by AIC
from the likelihood each dataset's noise calls for, flagged fits last, structurally identical
laws merged; see ``ranking``) and states, per group:

* best / headline: the top candidate is named "best" only when it fits (``goodness`` rule, in words
  ``rules.goodness``) and carries no plausibility flag; if it
  fails, the headline is "no registered law describes these data (best of a poor set: X)".
  Candidates within delta-AIC < 2 of it are named as indistinguishable by these data.
* series_vs_exact: where the paper's truncated series and the exact solution of the same law
  (a law of the F = k A u family) were both fitted, whether each one's slip changes sign, from
  the fitted trajectories (the series slip u0 (1 - b + b cos phi t) crosses zero when b > 1/2;
  the exact u0 exp(-b (1 - cos phi t)) never does).

The equivalence verdict, the noise threshold and the transfer test are left "not tested" / ""
here; their producers fill them (``fill_*`` hooks of the equivalence and transfer modules).
``frictionlab compare`` prints them (``commands.compare.answer_lines``); the report's first screen
renders them (``report/first_screen.py``).
"""
from __future__ import annotations

import math

import numpy as np

from .answers import Answer, group_of
from .ranking import NEAR_TIE, RankRow

POOR = "no registered law describes these data"


def make_answers(datasets, fits, ranking, groups) -> tuple[Answer, ...]:
    """One Answer per group of the fitted ``datasets`` (in order of first appearance)."""
    members: dict[str, list] = {}
    for ds in datasets:
        members.setdefault(group_of(ds), []).append(ds)
    out = []
    for label, dss in members.items():
        names = tuple(d.name for d in dss)
        pool = ranking if len(dss) == 1 else groups
        key = names[0] if len(dss) == 1 else label
        rows = [r for r in pool if r.dataset == key and r.rank is not None]
        kinds = {d.provenance.kind for d in dss}
        provenance = kinds.pop() if len(kinds) == 1 else "mixed"
        best, fits_ok, headline, goodness, details, short = _verdict(rows)
        details["likelihood"] = {f.datasets[0]: {"kind": f.stats.likelihood, "why": f.stats.likelihood_reason}
                                 for f in fits if f.ok and f.datasets[0] in names}
        series_text, series_numbers = series_vs_exact([f for f in fits if f.ok and f.datasets[0] in names])
        details["series_vs_exact"] = series_numbers
        if series_numbers:
            short["series"] = series_short(series_numbers)
        closer = ""
        if len(dss) == 1:
            closer, closer_short, numbers = _closer(rows, fits, names[0])
            if closer:
                details["closer"], short["closer"] = numbers, closer_short
        out.append(Answer(group=label, datasets=names, provenance=provenance, best=best, fits=fits_ok,
                          headline=headline, goodness=goodness, equivalence="not tested", noise_threshold="",
                          series_vs_exact=series_text, details=details, short=short, closer=closer))
    return tuple(out)


def not_fitted_answers(datasets, reasons: dict[str, str], fitted=()) -> tuple[Answer, ...]:
    """One Answer per group none of whose datasets was fitted because no law compared applies to them:
    the reason (``reasons``: dataset name -> why) as its headline. Groups with a fitted member are
    answered by ``make_answers``; their left-out members are named in the report's dataset list."""
    fitted_groups = {group_of(d) for d in fitted}
    members: dict[str, list] = {}
    for ds in datasets:
        if ds.name in reasons and group_of(ds) not in fitted_groups:
            members.setdefault(group_of(ds), []).append(ds)
    out = []
    for label, dss in members.items():
        why = list(dict.fromkeys(reasons[d.name] for d in dss))
        kinds = {d.provenance.kind for d in dss}
        out.append(Answer(group=label, datasets=tuple(d.name for d in dss), provenance=kinds.pop() if len(kinds) == 1
                          else "mixed", best=None, fits=False, headline="not fitted: " + "; ".join(why), goodness="",
                          equivalence="not tested", noise_threshold="", series_vs_exact="",
                          equivalence_series="not tested", details={"not_fitted": why}, short={"best": "not fitted: no law compared applies"}))
    return tuple(out)


def _verdict(rows: list[RankRow]):
    """(best, fits, headline, goodness text, details, short forms) from one group's ranked rows."""
    if not rows:
        return None, False, "no law could be fitted", "", {}, {"best": "no law could be fitted"}
    top = rows[0]
    firsts = [r for r in rows if r.rank == top.rank]
    best = " = ".join(dict.fromkeys(r.candidate for r in firsts))
    near = [r for r in rows if r not in firsts and not r.flags and r.aic - top.aic < NEAR_TIE]
    fits = bool(top.fits) and not top.flags
    g = top.goodness
    noise = {"known": "sigma known", "estimated": "sigma estimated from the data", "mixed": "sigma known and estimated",
             "stated": "stated numbers at their stated precision",
             "none": "no likelihood"}.get(top.likelihood, top.likelihood)
    goodness = f"{g.text if g else 'no test'}; {noise}"
    if fits:
        headline = f"best: {best}"
        short = f"{best} ✓"
        if near:
            headline += (f"; indistinguishable by these data from {', '.join(r.candidate for r in near)} "
                         f"(delta-AIC < {NEAR_TIE:g})")
            short += " ≈ " + " ≈ ".join(r.candidate for r in near)
    elif top.fits and top.flags:  # every candidate is flagged: the flag is part of the headline
        headline = f"best: {best}, flagged: {top.flags[0]}"
        short = f"{best} (flagged implausible)"
    elif top.fits is None:  # no test possible (too few points and no valid likelihood)
        headline = f"fit not testable (top-ranked by AIC: {best}): {g.reason if g else 'no goodness of fit'}"
        short = f"untestable (lowest AIC: {best})"
    else:
        headline = f"{POOR} (best of a poor set: {best})"
        short = f"no law fits (best of a poor set: {best})"
    second = next((r for r in rows if r not in firsts), None)
    details = {"candidate": best, "rank_rows": len(rows), "aic": top.aic, "likelihood": top.likelihood,
               "chi2_p": top.chi2_p, "runs_p": top.runs_p, "lag1": top.lag1, "fits_rule": g.reason if g else "",
               "flags": list(top.flags), "plausibility": list(top.flags), "members": list(top.members),
               "parameterizations": top.parameterizations,
               "indistinguishable_from": [r.candidate for r in near],
               "delta_aic_to_next": (second.aic - top.aic) if second else math.nan,
               "next": second.candidate if second else ""}
    return best, fits, headline, goodness, details, {"best": short, "goodness": g.short if g else "not testable"}


def _slip_zero(tr) -> float | None:
    """First time [s] the slip changes sign (linear interpolation), or None."""
    u = tr.u
    s = np.sign(u)
    idx = np.nonzero((s[:-1] > 0) & (s[1:] < 0) | (s[:-1] < 0) & (s[1:] > 0))[0]
    if not idx.size:
        return None
    i = int(idx[0])
    return float(tr.t[i] - u[i] * (tr.t[i + 1] - tr.t[i]) / (u[i + 1] - u[i]))


def series_short(numbers: dict) -> str:
    """'series slip u = 0 at 309 / 338 us; exact never' from ``series_vs_exact``'s numbers."""
    def when(key):
        ts = [v[key] for v in numbers.values()]
        if all(t is None for t in ts):
            return "never"
        return "at " + " / ".join("never" if t is None else f"{t * 1e6:.0f}" for t in ts) + " µs"
    return f"series slip u = 0 {when('slip_zero_series_s')}; exact {when('slip_zero_exact_s')}"


def _closer(rows, fits, name: str) -> tuple[str, str, dict]:
    """Vuong's test of the two best-ranked candidates of dataset ``name`` (``vuong.closer_sentence``)."""
    from .vuong import closer_sentence

    ranked = sorted((r for r in rows if r.rank is not None), key=lambda r: r.rank)
    chosen = []
    for r in ranked:
        f = next((f for f in fits if f.ok and f.law == r.law and f.solver == r.solver and f.datasets == (name,)), None)
        if f is not None and f.law not in {c.law for c in chosen}:
            chosen.append(f)
        if len(chosen) == 2:
            return closer_sentence(*chosen)
    return "", "", {}


def series_vs_exact(fits) -> tuple[str, dict]:
    """What the paper's truncation does, from the fits of one group: per dataset and law fitted both by
    'series' and exactly, the b of the series fit, when each fitted slip changes sign (if ever) and
    the AIC difference. Returns (one sentence, numbers by dataset)."""
    from ...physics.law import AreaSlipForm
    from ...physics.registry import get_law

    numbers, sentences = {}, []
    by = {(f.datasets[0], f.law, f.solver): f for f in fits if len(f.datasets) == 1}
    simplest_first = sorted(by.items(), key=lambda kv: (len(get_law(kv[0][1]).params), kv[0][1]))
    for (name, law_name, solver), sf in simplest_first:
        if solver != "series" or name in numbers:
            continue
        ef = by.get((name, law_name, "exact"))
        law = get_law(law_name)
        d = sf.per_dataset[0]
        form = law.form(d.params)
        sc = d.scene
        if ef is None or not isinstance(form, AreaSlipForm) or d.target.t is None \
                or not hasattr(sc.area, "peak") or not hasattr(sc.area, "contact_time"):
            continue
        b = form.k * sc.area.peak * sc.area.contact_time / (sc.mass * math.pi)
        t = np.linspace(0.0, sc.area.contact_time, 2001)
        t_series = _slip_zero(d.trajectory(law, t))
        ex = ef.per_dataset[0].trajectory(law, t)
        t_exact = _slip_zero(ex)
        numbers[name] = {"law": law_name, "b_series": b, "slip_zero_series_s": t_series,
                         "slip_zero_exact_s": t_exact, "min_exact_slip_over_u0": float(np.min(ex.u) / sc.u0),
                         "delta_aic_exact_minus_series": ef.stats.aic - sf.stats.aic}
        series = (f"crosses zero at {t_series * 1e6:.0f} us" if t_series is not None else "never crosses zero")
        exact = (f"crosses zero at {t_exact * 1e6:.0f} us" if t_exact is not None
                 else f"never does (its minimum is {np.min(ex.u) / sc.u0:.2f} u0)")
        gain = ef.stats.aic - sf.stats.aic
        sentences.append(f"{name}: the series slip {series} (b = {b:.2f}); the exact solution's slip {exact}; "
                         f"the series {'better' if gain >= 0 else 'worse'} by delta-AIC {abs(gain):.1f}")
    order = [n for n in dict.fromkeys(f.datasets[0] for f in fits) if n in numbers]
    sentences.sort(key=lambda text: next(i for i, n in enumerate(order) if text.startswith(n + ":")))
    return "; ".join(sentences), {n: numbers[n] for n in order}
