"""A group's equivalence answer from its members' discrimination tests (``equivalence.py``).

Members are tested separately; the group's verdict uses Holm's step-down (1979) across them at the
one stated ALPHA: the member two-sided p-values sorted, the i-th smallest of m compared with
ALPHA / (m - i + 1), stopping at the first that is not below. A group is **not equivalent** if Holm
rejects at some member, **equivalent** if every member says so, else **cannot tell at this noise**.
When the members' own verdicts differ, the answer names them.
"""
from __future__ import annotations

import math

import attrs

from ..core.display import unit
from .equivalence import ALPHA, PAIRS


def holm(ps: list[float], alpha: float = ALPHA) -> list[bool]:
    """Which of the p-values Holm's step-down rejects at family-wise level ``alpha``."""
    order = sorted(range(len(ps)), key=lambda i: ps[i])
    out = [False] * len(ps)
    for rank, i in enumerate(order):
        if not ps[i] < alpha / (len(ps) - rank):
            break
        out[i] = True
    return out


def group_verdict(es) -> tuple[str, str]:
    """(verdict, disagreement note) of a group's tested members ``es`` (one pair, one solver kind)."""
    es = [e for e in es if e.ok]
    if not es:
        return "not tested", ""
    rejected = holm([e.p for e in es])
    if any(rejected):
        verdict = "not equivalent"
    elif all(e.verdict == "equivalent" for e in es):
        verdict = "equivalent"
    else:
        verdict = "cannot tell at this noise"
    own = {e.dataset: ("not equivalent" if r else e.verdict if e.verdict != "not equivalent" else
                       "not equivalent alone, not after Holm") for e, r in zip(es, rejected)}
    note = ""
    if len(set(own.values())) > 1:
        note = "members disagree: " + "; ".join(f"{d}: {v}" for d, v in own.items())
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


def group_answer(results, datasets, pair: tuple[str, str] = PAIRS[0]) -> dict:
    """The equivalence fields of one group's ``answers.Answer`` from the tests of ``pair`` (default the
    paper's: wear against area-rate) on the member ``datasets`` (names): ``equivalence`` (the exact
    or numerical law), ``equivalence_series`` (the paper's series), ``noise_threshold`` (the sentence
    of each member), ``short`` and ``details``; 'not tested' without a test."""
    names = set(datasets)
    mine = [e for e in results if e.dataset in names and (e.law_a, e.law_b) == pair]
    full = [e for e in mine if not e.involves_series]
    series = [e for e in mine if e.involves_series]
    (v_full, n_full), (v_series, n_series) = group_verdict(full), group_verdict(series)
    text = ""
    if _thresholds(full):
        text = _thresholds(full)
        if _thresholds(series):
            text += f"; the paper's series of {pair[0]}: {_thresholds(series)}"
    elif _thresholds(series):
        text = f"the paper's series of {pair[0]}: {_thresholds(series)}"
    tested = [(v, how) for v, how in ((v_full, "exact"), (v_series, "series")) if v != "not tested"]
    short = {"equivalence": (f"{v_full} (exact and series)" if len(tested) == 2 and v_full == v_series else
                             "; ".join(f"{v} ({how})" for v, how in tested) or "not tested")}
    if _threshold_short(full or series):
        short["threshold"] = _threshold_short(full or series) + ("" if full else " [series]")
    qual = {f"{e.dataset} [{e.solver_a}]": e.qualitative["verdict"] + (f" ({e.qualitative['differs']})"
                                                                       if e.qualitative.get("differs") else "")
            for e in mine if e.ok and e.qualitative.get("verdict") not in (None, "not applicable")}
    if qual:
        short["qualitative"] = "; ".join(f"{k}: {v}" for k, v in qual.items())
        kinds = {v.split(" (")[0] for v in qual.values()}
        short["equivalence"] += "; " + (kinds.pop() if len(kinds) == 1 else "qualitatively equivalent on some, not all")
        text = f"Qualitatively (do the fitted curves share the data's features?): {short['qualitative']}. " + text
    notes = [f"{how}: {n}" for n, how in ((n_full, "exact"), (n_series, "series")) if n]
    if notes:
        short["equivalence"] += " — " + "; ".join(notes)
    return {"equivalence": v_full, "equivalence_series": v_series, "noise_threshold": text, "short": short,
            "details": {"equivalence": [e.as_dict() | {"t_a": None, "t_b": None} for e in mine],
                        "equivalence_disagreement": notes}}


def fill_answers(answers, results) -> tuple:
    """``answers`` (answers.Answer rows) with their equivalence fields filled from the tests ``results``."""
    out = []
    for a in answers:
        g = group_answer(results, a.datasets)
        out.append(attrs.evolve(a, equivalence=g["equivalence"], equivalence_series=g["equivalence_series"],
                                noise_threshold=g["noise_threshold"], details={**a.details, **g["details"]},
                                short={**a.short, **g["short"]}))
    return tuple(out)
