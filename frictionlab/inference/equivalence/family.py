"""One error rate for a report's equivalence tests, and a group's answer from its members' tests.

Family (``adjust_family``): every hypothesis the report's tests decide (per tested pair: 'neither law is
rejected', from the two-sided p of ``equivalence``, and 'the curves differ by delta or more', from
p_within) is one family, adjusted by Holm's step-down (1979) at the one stated ALPHA: the chance that any
'different' or 'equivalent within delta' of the report is wrong is at most ALPHA, whatever the other
verdicts. With ``family="group"`` (on request) Holm runs within each dataset group instead: that rate
then holds per group, not for the report. Pairs whose laws both fail their fit tests have no p-value and
are not in the family.

A group's answer (``group_verdict``): **different** if a member is, **equivalent within delta** if every
member is (an intersection-union test: no further adjustment), **both fail their fit tests** if every
member's pair does, else **cannot tell at this noise**. When the members' verdicts differ, the answer
names them.
"""
from __future__ import annotations

import math

import attrs

from ...core.display import unit
from .discrimination import ALONE, ALPHA, BOTH_FAIL, CANNOT, DIFFERENT, PAIRS, WITHIN, decide

#: The family of a pair without a test (both laws fail their fit tests): none, it has no p-value.
NO_FAMILY = "none: no p-value (both laws fail their fit tests)"
#: The families a report's p-values may be adjusted in (``adjust_family``): the whole report (the default) or
#: each dataset group.
FAMILIES = ("report", "group")


def holm(ps: list[float], alpha: float = ALPHA) -> list[bool]:
    """Which of the p-values Holm's step-down rejects at family-wise level ``alpha``."""
    return [p < alpha for p in holm_adjusted(ps)]


def holm_adjusted(ps: list[float]) -> list[float]:
    """Holm-adjusted p-values: the i-th smallest of m times (m - i + 1), running maximum, at most 1; a p-value
    is rejected at family-wise level alpha exactly when its adjusted value is below alpha."""
    order = sorted(range(len(ps)), key=lambda i: ps[i])
    out, running = [1.0] * len(ps), 0.0
    for rank, i in enumerate(order):
        running = max(running, min(1.0, (len(ps) - rank) * ps[i]))
        out[i] = running
    return out


def family_text(family: str, n: int, label: str = "") -> str:
    """How the p-values were adjusted, for the verdict sentences and the report."""
    if n <= 1:
        return ALONE
    if family == "group":
        return f"Holm over the {n} hypotheses of group {label} (per-group rule, on request)"
    return f"Holm over the {n} hypotheses of this report"


def adjust_family(results, family: str = "report", group_of=None) -> tuple:
    """``results`` (EquivalenceResult) with adjusted p-values and their verdicts decided again (module
    docstring). group_of: dataset name -> group label (for ``family="group"``)."""
    if family not in FAMILIES:
        from ...core.errors import ParameterError

        raise ParameterError(f"family must be one of {', '.join(FAMILIES)}, got {family!r}")
    results = list(results)
    members: dict[str, list[int]] = {}
    for i, e in enumerate(results):
        if e.ok and not e.tested:
            results[i] = attrs.evolve(e, family=NO_FAMILY)
            continue
        if e.tested and math.isfinite(e.p) and math.isfinite(e.p_within):
            label = (group_of or {}).get(e.dataset, e.dataset) if family == "group" else "report"
            members.setdefault(label, []).append(i)
    for label, idx in members.items():
        ps = [results[i].p for i in idx] + [results[i].p_within for i in idx]
        adj = holm_adjusted(ps)
        text = family_text(family, len(ps), label)
        for k, i in enumerate(idx):
            results[i] = decide(attrs.evolve(results[i], p_adjusted=adj[k], p_within_adjusted=adj[len(idx) + k],
                                             family=text))
    return tuple(results)


def group_verdict(es) -> tuple[str, str]:
    """(verdict, disagreement note) of a group's members ``es`` (one pair, one solver kind), each decided."""
    es = [e for e in es if e.ok]
    if not es:
        return "not tested", ""
    own = {e.dataset: e.verdict for e in es}
    kinds = set(own.values())
    if DIFFERENT in kinds:
        verdict = DIFFERENT
    elif kinds == {WITHIN}:
        verdict = WITHIN
    elif kinds == {BOTH_FAIL}:
        verdict = BOTH_FAIL
    else:
        verdict = CANNOT
    note = "members disagree: " + "; ".join(f"{d}: {v}" for d, v in own.items()) if len(kinds) > 1 else ""
    return verdict, note


def _thresholds(es) -> str:
    parts = []
    for e in es:
        if not math.isfinite(e.threshold):
            continue
        parts.append(f"on {e.dataset}: {e.threshold_text()}")
    return "; ".join(parts)


def _threshold_short(es) -> str:
    """'differ unless σ > 1.8 deg (σ = 0.5 deg)'; members joined by ' / ' in one unit."""
    es = [e for e in es if math.isfinite(e.threshold)]
    if not es:
        return ""
    if all(e.threshold == 0 for e in es):
        return "one curve: equal at any noise"
    if all(e.observable == "stated" for e in es):
        return "differ unless precision > " + " / ".join(f"{e.threshold / e.sigma:.2g}×" for e in es) + " stated"
    name, f = unit(es[0].observable)
    if len({e.observable for e in es}) > 1:
        return "differ unless σ > " + " / ".join(e.threshold_text() for e in es)
    thr = " / ".join(_num2(e.threshold * f) for e in es)
    sig = " / ".join(dict.fromkeys(_num2(e.sigma * f) for e in es))
    return f"differ unless σ > {thr} {name} (σ = {sig} {name})"


def _num2(x: float) -> str:
    """Two significant figures (whole numbers from 100 on): 1.8, 0.27, 150, 1,200."""
    r = float(f"{x:.2g}")
    return f"{r:,.0f}" if abs(r) >= 100 else f"{r:g}"


def _short(verdict: str, es) -> str:
    """A group's verdict in a few words with its decisive number: 'different (p = 2e-06)', 'equivalent within
    δ = 1σ (bound 0.4σ)', 'both fail their fit tests'."""
    from ..diagnostics.goodness import p_short

    tested = [e for e in es if e.tested]
    if verdict == DIFFERENT:
        p = min(e.p_adjusted for e in tested if e.verdict == DIFFERENT)
        return f"different (p {'' if p == 0 else '= '}{p_short(p)})"
    if verdict == WITHIN:
        worst = max(tested, key=lambda e: e.upper / e.margin)
        return f"equivalent within δ ({worst.margin_text.split(', ')[0]}; bound {worst.quantity(worst.upper)})"
    return verdict


def group_answer(results, datasets, pair: tuple[str, str] = PAIRS[0]) -> dict:
    """The equivalence fields of one group's ``answers.Answer`` from the tests of ``pair`` (default the
    paper's: wear against area-rate) on the member ``datasets`` (names): ``equivalence`` (the exact
    or numerical law), ``equivalence_series`` (the paper's series), ``noise_threshold`` (the sentence
    of each member), ``short`` and ``details``; 'not tested' without a test. Every text is whole sentences."""
    from .discrimination import sentence, sentences

    names = set(datasets)
    mine = [e for e in results if e.dataset in names and (e.law_a, e.law_b) == pair]
    full = [e for e in mine if not e.involves_series]
    series = [e for e in mine if e.involves_series]
    (v_full, n_full), (v_series, n_series) = group_verdict(full), group_verdict(series)
    parts = []
    if _thresholds(full):
        parts.append(_thresholds(full))
    if _thresholds(series):
        parts.append(f"the truncated series of {pair[0]}: {_thresholds(series)}")
    text = sentences(*parts)
    tested = [(v, how, es) for v, how, es in ((v_full, "exact", full), (v_series, "series", series))
              if v != "not tested"]
    shorts = [(_short(v, es), how) for v, how, es in tested]
    short = {"equivalence": (f"{shorts[0][0]} (exact and series)" if len(shorts) == 2 and v_full == v_series
                             and v_full in (BOTH_FAIL, CANNOT) else
                             "; ".join(f"{v} ({how})" for v, how in shorts) or "not tested")}
    if _threshold_short(full or series):
        short["threshold"] = _threshold_short(full or series) + ("" if full else " [series]")
    qual = {f"{e.dataset} [{e.solver_a}]": _qual_short(e) for e in mine
            if e.ok and e.qualitative.get("verdict") not in (None, "not applicable")}
    qualitative = ""
    if qual:
        short["qualitative"] = "; ".join(f"{k}: {v}" for k, v in qual.items())
        kinds = {v.split(" (")[0].split(";")[0] for v in qual.values()}
        short["equivalence"] += "; " + (kinds.pop() if len(kinds) == 1 else "qualitatively equivalent on some, not all")
        qualitative = sentence(f"qualitatively (do the fitted curves share the data's features?): {short['qualitative']}")
    notes = [f"{how}: {n}" for n, how in ((n_full, "exact"), (n_series, "series")) if n]
    if notes:
        short["equivalence"] += " — " + "; ".join(notes)
    return {"equivalence": v_full, "equivalence_series": v_series, "noise_threshold": text, "qualitative": qualitative,
            "short": short,
            "details": {"equivalence": [e.as_dict() | {"t_a": None, "t_b": None, "x_a": None, "x_b": None}
                                        for e in mine],
                        "equivalence_disagreement": notes}}


def _qual_short(e) -> str:
    """'qualitatively equivalent; peak times 33 µs apart (quantitative)' of one test."""
    q = e.qualitative
    out = q["verdict"] + (f" ({q['differs']})" if q.get("differs") else "")
    peak = q.get("peak_time") or {}
    if peak.get("differs"):
        out += f"; peak times {peak['shift'] * 1e6:.0f} µs apart (quantitative)"
    return out


def fill_answers(answers, results) -> tuple:
    """``answers`` (answers.Answer rows) with their equivalence fields filled from the tests ``results``."""
    out = []
    for a in answers:
        g = group_answer(results, a.datasets)
        out.append(attrs.evolve(a, equivalence=g["equivalence"], equivalence_series=g["equivalence_series"],
                                noise_threshold=g["noise_threshold"], qualitative=g["qualitative"],
                                details={**a.details, **g["details"]}, short={**a.short, **g["short"]}))
    return tuple(out)
