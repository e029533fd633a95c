"""The first screen of a multi-step record: does one parameter set describe the up and the down steps, for which
state law; each step's parameters with the window they come from; the shared set and the whole-record fit; the
parameters at a bound with what that means. Reads only the fits (``inference.record_steps.LawSteps``)."""
from __future__ import annotations

from .velstep import cell

COLUMNS = (("a", "a"), ("b", "b"), ("a-b", "a - b"), ("Dc", "Dc [um]"), ("k", "k [1/um]"))
#: A law parameter beyond a, b and Dc, shown (after Dc) where a law fitted has it: Nagata's c.
EXTRA = (("c", "c"),)


def _table(rows: list[list[str]]) -> list[str]:
    widths = [max(len(r[j]) for r in rows) for j in range(len(rows[0]))]
    return ["  " + "  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]


def _law(name: str) -> str:
    return name.replace("rate-state-", "")


def _columns(results) -> tuple:
    """COLUMNS, with each of EXTRA after Dc where a law of ``results`` has that parameter."""
    fits = [f for r in results for f in r.steps + (r.joint,) if f is not None and f.ok]
    extra = tuple(c for c in EXTRA if any(c[0] in f.params for f in fits))
    return COLUMNS[:4] + extra + COLUMNS[4:]


def _quantities(f, columns) -> list[str]:
    q = f.velstep.rows[0].quantities if f.ok and f.velstep is not None else {}
    return [cell(q.get(key)) for key, _ in columns]


def screen(title: str, steps: list[dict], results, answer: str, joint_note: str = "") -> list[str]:
    """Lines of the first screen. ``steps``: per step window {'name', 'label' (e.g. '0.2 -> 2'), 'direction',
    'window' (lines and samples), 'note' (where it starts and why)}; ``results``: LawSteps per law."""
    out = [title, "", answer]
    out += [f"  {r.verdict()}" for r in results]
    failing = sorted({s["name"] for r in results for s, f in zip(steps, r.steps)
                      if f.ok and f.goodness is not None and f.goodness.short.startswith("fails")})
    if failing:
        out.append(f"  note: a law fails its goodness-of-fit tests on {', '.join(failing)} (structure it leaves, or noise "
                   "its model does not describe): the likelihood ratio's chi-square reference, and its p-value, are "
                   "approximate")
    out += ["", "Each step's own parameters (value ± standard error), each from its own window (below):"]
    columns = _columns(results)
    rows = [["step", "V [um/s]", "", "law"] + [h for _, h in columns] + ["goodness of fit"]]
    for i, s in enumerate(steps):
        for r in results:
            f = r.steps[i]
            good = f.goodness.short if f.ok and f.goodness is not None else f"{f.status}: {f.reason}"[:60]
            rows.append([s["name"], s["label"], s["direction"], _law(r.law)] + _quantities(f, columns) + [good])
    out += _table(rows)
    shared = [r for r in results if r.shared is not None and r.shared.status == "ok"]
    if shared:
        extra = [key for key, _ in columns if key not in dict(COLUMNS)]
        names = ", ".join(["a", "b", "Dc"] + extra)
        out += ["", f"One set for every step ({names} shared; k, mu_ss and the trend each window's own):"]
        rows = [["law", "a", "b", "a - b", "Dc [um]"] + extra + ["-2 ln L shared", "per step"]]
        for r in shared:
            p = r.shared.shared
            rows.append([_law(r.law), f"{p.get('a', float('nan')):.4g}", f"{p.get('b', float('nan')):.4g}",
                         f"{p.get('a', float('nan')) - p.get('b', float('nan')):.3g}",
                         f"{p.get('Dc', float('nan')) * 1e6:.4g}"]
                        + [f"{p[key]:.4g}" if key in p else "—" for key in extra]
                        + [f"{r.shared.chi2_shared:.6g}", f"{r.shared.chi2_separate:.6g}"])
        out += _table(rows)
    joint = [r for r in results if r.joint is not None]
    if joint:
        out += ["", f"The whole record as one history (every step and hold driving one simulation{joint_note}):"]
        rows = [["law"] + [h for _, h in columns] + ["goodness of fit"]]
        for r in joint:
            f = r.joint
            good = f.goodness.short if f.ok and f.goodness is not None else f"{f.status}: {f.reason}"[:60]
            rows.append([_law(r.law)] + _quantities(f, columns) + [good])
        out += _table(rows)
    out += ["", "Windows (where each step's parameters come from):"]
    out += [f"  {s['name']} ({s['label']} um/s): {s['window']}; {s['note']}" for s in steps]
    said = []
    for r in results:
        for s, f in zip(steps, r.steps):
            said += [f"  {s['name']}, {_law(r.law)}: {t}" for t in (f.velstep.bounds if f.ok and f.velstep else ())]
        if r.joint is not None and r.joint.ok and r.joint.velstep is not None:
            said += [f"  whole record, {_law(r.law)}: {t}" for t in r.joint.velstep.bounds]
    out += ["", "Parameters at a bound, and what it means:"] + (said or ["  none"])
    missed = [f"  {s['name']}, {_law(r.law)}: {t}" for r in results for s, f in zip(steps, r.steps)
              for t in (f.velstep.missing if f.ok and f.velstep else ())]
    if missed:
        out += ["", "What the data show that a law misses:"] + missed
    return out
