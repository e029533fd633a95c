"""The first screen: the verdict table (``Comparison.answers``) and the figure of the central finding.

The verdict table only renders the answers the verdict layer filled (``frictionlab/inference/answers.py``);
columns without data are named in one line under it, and groups without a fitted law fold into one
line. Without answers it shows what the comparison does hold, labelled as such (the AIC ranking's
first place and the equivalence analysis' verdict), never a verdict of its own. The finding, where
a dataset's spin falls and the paper's truncated series of a F = k A u law has its slip cross zero:
that series against the exact solution of the same law, spin above and the slip u(t) of each below,
with the crossing time (computed here from the fitted series). Elsewhere the figure and sentences
of ``data_view`` describe the compared data.
"""
from __future__ import annotations

import attrs
import numpy as np

from ..core.display import fmt_time
from ..inference.answers import group_of, unfitted
from ..solve.solvers.series import slip_zero
from . import figures, velstep
from .data_view import data_views, describe, spin_falls
from .data_view import title as view_title
from .doc import Section
from .text import PROVENANCE_WORDS, sig

TITLE = "Answers"
#: (Answer.short key, column header) of the verdict table; each cell is the short form, the full
#: sentences follow in a folded list right below the table.
COLUMNS = (("best", "best law"), ("goodness", "goodness of fit"),
           ("equivalence", "λAu ≡ μN + μη′dA/dt?"), ("threshold", "noise threshold"),
           ("series", "series vs exact"), ("transfer", "one parameter set for all conditions?"))
#: characters a table cell shows (more: cut, the full text is in the notes)
CELL_LIMIT = 70
#: (Answer field, label) of the full sentences in the notes below the table.
NOTES = (("headline", ""), ("goodness", "Goodness"), ("equivalence", "λAu against μN + μη′dA/dt, exact"),
         ("equivalence_series", "The paper's series"), ("noise_threshold", "Noise threshold"),
         ("series_vs_exact", "Series vs exact"), ("transfer", "Across conditions"))


@attrs.frozen
class SeriesFinding:
    """The series and the exact (or ODE) fit of one law on one impact, and where the series' slip crosses zero."""

    dataset: object
    series: object  # FitResult
    full: object  # FitResult
    t_cross: float | None  # s; None if the series' slip stays positive
    contact_time: float  # s
    full_min_slip: float  # m/s, the smallest slip of the exact (or ODE) solution during contact


def series_findings(c, law_order=("wear", "couette")) -> list[SeriesFinding]:
    """Per impact dataset with a 'series' fit and a non-series fit of the same law: the finding (one law each)."""
    out = []
    for d in c.fitted_datasets:
        if "t" not in d.columns:
            continue
        laws = sorted({f.law for f in c.fits_on(d.name) if f.ok and f.solver == "series"},
                      key=lambda x: (law_order.index(x) if x in law_order else len(law_order), x))
        for law in laws:
            ser = c.fit_for(d.name, law, "series")
            full = next((f for f in c.fits_on(d.name) if f.law == law and f.ok and f.solver != "series"), None)
            if full is None:
                continue
            tc = getattr(d.scene.area, "contact_time", float(d.t[-1]))
            t = np.linspace(0.0, float(tc), 20001)
            u = ser.per_dataset[0].trajectory(law, t)["u"]
            u_full = full.per_dataset[0].trajectory(law, t[::20])["u"]
            out.append(SeriesFinding(d, ser, full, slip_zero(t, u), float(tc), float(np.min(u_full))))
            break
    return out


def finding_sentence(f: SeriesFinding) -> str:
    if f.t_cross is None:
        return (f"On {f.dataset.name} the truncated series' slip stays positive up to t_c, so it cannot explain "
                "a fall of the spin by itself.")
    text = (f"On {f.dataset.name} the paper's truncated series of {f.series.law} has its slip u(t) cross zero at "
            f"{fmt_time(f.t_cross, f.contact_time)} (t_c = {fmt_time(f.contact_time)}): from there its friction "
            "pushes the other way and the spin falls.")
    if f.full_min_slip > 0:
        text += (f" The {f.full.solver} solution of the same law keeps u > 0 (at least {f.full_min_slip:.3g} m/s), "
                 "so its spin never falls: the fall comes from the truncation, not from the law.")
    return text


def finding_text(shown) -> str:
    """The first finding in full, the others by their numbers."""
    text = finding_sentence(shown[0])
    more = [f"on {f.dataset.name} at {fmt_time(f.t_cross, f.contact_time)} (t_c {fmt_time(f.contact_time)})"
            for f in shown[1:] if f.t_cross is not None]
    return text + (" The same " + ("crossing" if len(more) == 1 else "crossings") + ": " + "; ".join(more) + "."
                   if more else "")


#: what each column would have said, for the one line naming the columns this comparison has no data for
ABSENT = {"best": "a best law", "goodness": "a goodness-of-fit test",
          "equivalence": "the equivalence test of λAu and μN + μη′dA/dt (no dataset fitted with both)",
          "threshold": "a noise threshold", "series": "the paper's series against the exact solution (no series fitted)",
          "transfer": "one parameter set across conditions (no group of two or more datasets)"}


def _answer_table(sec: Section, answers):
    """The verdict table: groups without a fitted law fold into one line under it, columns without data go."""
    shown = [a for a in answers if a.best is not None]
    cols = [(key, head) for key, head in COLUMNS if any(a.cell(key) for a in shown)]
    rows, notes = [], []
    for a in shown:
        cells = [_clip(a.cell(key)) or "—" for key, _ in cols]
        flags = _flags(a)
        if flags and "implausible" not in cells[0]:
            cells[0] += " ⚠ implausible"
        rows.append([f"**{a.group}**"] + cells)
        parts = [f"{label}: {getattr(a, field)}" if label else getattr(a, field)
                 for field, label in NOTES if getattr(a, field) and getattr(a, field) != "not tested"]
        if flags:
            parts.append("implausible: " + "; ".join(flags))
        notes.append(f"**{a.group}** ({', '.join(a.datasets)}; {a.provenance}): " + ". ".join(parts) + ".")
    if rows:
        sec.table(["dataset group"] + [h for _, h in cols], rows)
        sec.more("Each verdict in full (datasets, tests, p-values, thresholds per dataset)", notes)
    for reason, groups, hints in unfitted(answers):
        head, _, why = reason.partition(": ")
        sec.p(f"{head[0].upper()}{head[1:]}" + (f" ({why})" if why else "") + f": {', '.join(groups)}"
              + "".join(f"; registered laws that apply: {h}" for h in hints) + ".")
    absent = [ABSENT[key] for key, _ in COLUMNS if key not in dict(cols)]
    if shown and absent:
        sec.p("Not in this comparison: " + "; ".join(absent) + ".")


def _clip(text: str, limit: int = CELL_LIMIT) -> str:
    """A cell of at most about ``limit`` characters: a long sentence (a producer without a short form) is cut
    at a word and ends in '…'; it is in full in the notes below the table."""
    if len(text) <= limit:
        return text
    return text[:limit].rsplit(" ", 1)[0].rstrip(",;:") + " …"


def _flags(a) -> list[str]:
    flags = a.details.get("plausibility") if isinstance(a.details, dict) else None
    if not flags:
        return []
    return [str(f) for f in (flags if isinstance(flags, (list, tuple)) else [flags])]


def _fallback_table(sec: Section, c, findings):
    by_ds = {f.dataset.name: f for f in findings}
    rows = []
    for d in c.fitted_datasets:
        best = [r for r in c.ranking if r.dataset == d.name and r.rank == 1]
        eq = [f"{e.verdict} [wear {e.solver_a}]" for e in c.equivalence
              if e.dataset == d.name and e.ok and (e.law_a, e.law_b) == ("wear", "area-rate")]
        thr = [e.threshold_text() for e in c.equivalence
               if e.dataset == d.name and e.ok and (e.law_a, e.law_b) == ("wear", "area-rate")]
        f = by_ds.get(d.name)
        ser = "—" if f is None else ("slip crosses zero at " + fmt_time(f.t_cross, f.contact_time)
                                     if f.t_cross is not None else "slip stays positive")
        rows.append([f"**{d.name}** ({group_of(d)}; {d.provenance.kind})", _tied(best),
                     sig(best[0].redchi) if best else "", "; ".join(eq) or "not tested", "; ".join(thr), ser])
    sec.table(["dataset (group; provenance)", "lowest AIC (not a fit test)", "its reduced χ²",
               "λAu ≡ μN + μη′dA/dt? (discrimination test)", "noise threshold", "series slip"], rows)
    for tr in c.transfer:
        sec.p(f"Across conditions ({tr.group}): {tr.answer()}.")
    sec.p("Not in this comparison: " + ABSENT["goodness"] + ".")


def _tied(best) -> str:
    """'wear = couette [series]' for tied candidates of one solver (one functional form, one entry)."""
    if not best:
        return "no law could be fitted"
    by_solver: dict[str, list[str]] = {}
    for r in best:
        by_solver.setdefault(r.solver, []).append(r.law)
    return " = ".join(f"{' = '.join(laws)} [{s}]" for s, laws in by_solver.items())


def build(ctx) -> Section:
    c = ctx.c
    sec = Section(TITLE, open=True)
    kinds = {}
    for d in c.fitted_datasets:
        kinds.setdefault(d.provenance.kind, []).append(d.name)
    note = ""
    if set(kinds) - {"measured"}:
        note = (("No dataset here is a measurement: " if "measured" not in kinds else "Not every dataset is measured: ")
                + "; ".join(f"{len(v)} {PROVENANCE_WORDS.get(k, k).split(',')[0]}" for k, v in kinds.items())
                + " (see 'Datasets and provenance'). ")
    findings = series_findings(c)
    ctx.json["series_slip_zero_s"] = {f.dataset.name: f.t_cross for f in findings}
    if c.answers:
        if note:
            sec.warn(note)
        _answer_table(sec, c.answers)
    else:
        sec.warn(note + "The verdict layer gave no answers for this comparison (`Comparison.answers` is empty): no "
                 "law is declared to fit, and no goodness-of-fit test is shown. "
                 "The table shows what the comparison holds: the lowest AIC (a relative ranking, not a test that "
                 "the law fits), its reduced χ², and the discrimination test's verdict and noise threshold.")
        _fallback_table(sec, c, findings)
    velstep.first_screen(sec, c)  # each measured velocity step: its parameters beside its figure
    story = [f for f in _pick(findings) if f.t_cross is not None and spin_falls(f.dataset)]
    if story:
        sec.fig("finding.png", "Spin (top) and slip u(t) (bottom) of the truncated series and the exact solution "
                "of the same law, fitted to the same data; dotted: where the series' slip crosses zero.",
                lambda: figures.finding_figure(story), side="**Why the paper's spin falls.** " + finding_text(story))
        return sec
    views = data_views(c, findings)
    if views:
        sec.fig("finding.png", "The data with the top-ranked candidates (#rank, ΔAIC)" + (
            "; below, where the paper's series was fitted, the slip u(t) of the series and of the exact "
            "solution of the same law" if any(v.series for v in views) else "") + ".",
                lambda: figures.data_figure(views, view_title(views)),
                side="**What the data show.** " + " ".join(describe(v) for v in views))
    return sec


def _pick(findings, n: int = 2):
    """At most n findings, those with a zero crossing first (then in dataset order)."""
    return sorted(findings, key=lambda f: f.t_cross is None)[:n]

