"""The first screen: the verdict table (``Comparison.answers``), what accuracy costs, and the figure of the data.

The verdict table only renders the answers the verdict layer filled (``frictionlab/inference/verdicts/answers.py``);
columns without data are named in one line under it, and groups without a fitted law fold into one
line. Without answers it shows what the comparison does hold, labelled as such (the AIC ranking's
first place and the equivalence analysis' verdict), never a verdict of its own. The full sentences of each
row follow, folded, each part a labelled run of whole sentences; then, folded, what accuracy costs per law and
dataset (``inference.cost.accuracy``). The figure (``data_view``) draws each group's data with its top-ranked
candidates, and the slip of the truncated series against the exact solution where that series is among them.

Kinds of data with a first-screen block of their own plug in at one place, ``KIND_BLOCKS``: a dataset kind
mapped to a function ``block(ctx, sec, datasets)`` that adds its paragraphs, tables and figures for the
comparison's fitted datasets of that kind and returns the names of those it drew (None: all of them); those
are then left out of the generic figure. Measured velocity steps (``velstep``) have one.
"""
from __future__ import annotations

import math

import attrs
import numpy as np

from ..core.display import fmt_time
from ..inference.cost.accuracy import COMMAND as ACCURACY_COMMAND
from ..inference.verdicts.answers import group_of, unfitted
from ..inference.equivalence.discrimination import AREA_RATE, COULOMB, COUETTE, WEAR, sentence
from ..solve.solvers.series import slip_zero
from . import figures, velstep
from .data_view import describe, group_views, spin_falls
from .data_view import title as view_title
from .doc import Section
from .text import PROVENANCE_WORDS, sig

TITLE = "Answers"
#: (Answer.short key, column header) of the verdict table; each cell is the short form, the full
#: sentences follow in a folded list right below the table.
COLUMNS = (("best", "best law"), ("goodness", "goodness of fit"),
           ("equivalence", "λAu vs μN + μη′dA/dt"),
           ("threshold", "noise threshold"), ("series", "series vs exact"), ("accuracy", "what accuracy costs"),
           ("transfer", "one parameter set for all conditions?"), ("closer", "which law is closer"))
#: characters a table cell shows (more: cut, the full text is in the notes)
CELL_LIMIT = 70
#: (Answer field, label) of the full sentences in the notes below the table.
NOTES = (("headline", ""), ("goodness", "Goodness"), ("equivalence", "λAu against μN + μη′dA/dt, exact"),
         ("equivalence_series", "The truncated series of λAu against μN + μη′dA/dt"),
         ("qualitative", "Shared features"), ("noise_threshold", "Noise threshold"),
         ("series_vs_exact", "Series vs exact"), ("accuracy", "What accuracy costs"), ("transfer", "Across conditions"),
         ("closer", "Which law is closer"))
#: dataset kind -> block(ctx, sec, datasets) -> names drawn or None (all): a first-screen block of its own for the
#: fitted datasets of that kind (module docstring); the generic figure leaves the datasets it drew out.
KIND_BLOCKS: dict = {"spring-slider": lambda ctx, sec, datasets: velstep.first_screen(sec, ctx.c, datasets)}


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


#: what each column would have said, for the one line naming the columns this comparison has no data for
ABSENT = {"best": "a best law", "goodness": "a goodness-of-fit test",
          "equivalence": "the equivalence test of λAu and μN + μη′dA/dt (no dataset where both were fitted and tested)",
          "threshold": "a noise threshold", "series": "the truncated series against the exact solution (no series "
                                                                 "fitted)",
          "accuracy": f"what accuracy costs (it runs by default where cheap, unless --no-accuracy; `{ACCURACY_COMMAND}` "
                      "runs it everywhere)",
          "transfer": "one parameter set across conditions (no group of two or more datasets)",
          "closer": "which law is closer (no two laws with pointwise likelihoods on one dataset)"}


def _answer_table(sec: Section, answers, laws=()):
    """The verdict table: groups without a fitted law fold into one line under it, columns without data go
    (named in one line where they could apply to ``laws``, the laws compared)."""
    shown = [a for a in answers if a.best is not None]
    cols = [(key, head) for key, head in COLUMNS if any(a.cell(key) not in ("", "not tested") for a in shown)]
    rows, notes = [], []
    for a in shown:
        cells = [_clip(a.cell(key)) or "—" for key, _ in cols]
        flags = _flags(a)
        if flags and "implausible" not in cells[0]:
            cells[0] += " ⚠ implausible"
        rows.append([f"**{a.group}**"] + cells)
        notes.append(f"**{a.group}** ({', '.join(a.datasets)}; {a.provenance}): " + " ".join(note_parts(a, flags)))
    if rows:
        sec.table(["dataset group"] + [h for _, h in cols], rows)
        sec.more("Each verdict in full (datasets, tests, p-values, thresholds per dataset)", notes)
    absent = [ABSENT[key] for key, _ in COLUMNS if key not in dict(cols) and _could_apply(key, laws)]
    if shown and absent:
        sec.p("Not in this comparison: " + "; ".join(absent) + ".")


def _could_apply(key: str, laws) -> bool:
    """Whether a column absent from the verdict table is worth naming: the paper's pair and the truncated series
    only where the paper's laws were compared."""
    if key == "closer":  # said where it was tested, not missed elsewhere
        return False
    if key in ("equivalence", "threshold"):
        return {WEAR, AREA_RATE} <= set(laws)
    if key == "series":
        return bool({WEAR, AREA_RATE, COULOMB, COUETTE} & set(laws))
    return True


def _unfitted(sec: Section, answers):
    """One line per reason for the groups without a fitted law."""
    for reason, groups, hints in unfitted(answers):
        head, _, why = reason.partition(": ")
        sec.p(f"{head[0].upper()}{head[1:]}" + (f" ({why})" if why else "") + f": {', '.join(groups)}"
              + "".join(f"; registered laws that apply: {h}" for h in hints) + ".")


def note_parts(a, flags=()) -> list[str]:
    """The full sentences of one answer row: each field a labelled run of whole sentences ('**Label.** Text.'),
    so that no field's text can run into another's."""
    parts = []
    for field, label in NOTES:
        text = getattr(a, field)
        if not text or text == "not tested":
            continue
        parts.append((f"**{label}.** " if label else "") + sentence(text))
    if flags:
        parts.append("**Implausible.** " + sentence("; ".join(flags)))
    return parts


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
               "λAu vs μN + μη′dA/dt (equivalence test)", "noise threshold", "series slip"], rows)
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
        _answer_table(sec, c.answers, {f.law for f in c.fits})
    else:
        sec.warn(note + "The verdict layer gave no answers for this comparison (`Comparison.answers` is empty): no "
                 "law is declared to fit, and no goodness-of-fit test is shown. "
                 "The table shows what the comparison holds: the lowest AIC (a relative ranking, not a test that "
                 "the law fits), its reduced χ², and the discrimination test's verdict and noise threshold.")
        _fallback_table(sec, c, findings)
    own: dict[str, list] = {}
    for d in c.fitted_datasets:
        if d.kind in KIND_BLOCKS:
            own.setdefault(d.kind, []).append(d)
    drawn: set[str] = set()
    for kind, dss in own.items():
        shown = KIND_BLOCKS[kind](ctx, sec, dss)
        drawn |= {d.name for d in dss} if shown is None else set(shown)
    views = group_views(c, findings, skip=drawn)
    if ctx.group_page and len(views) == 1 and views[0].series is None:  # its dataset's fits, as drawn among them
        from .fits import fit_figure

        d = views[0].dataset
        fit_figure(sec, d, c.fits_on(d.name), [r for r in c.ranking if r.dataset == d.name],
                   f"{d.name}: the data ({d.provenance.kind}) with each law's best fit (ΔAIC from the lowest), as "
                   "'Fits' shows them.")
        sec.p(_side(views))
    elif views:
        shown = views[:MAX_PANELS]
        sec.fig("finding.png", "Per dataset group, one of its datasets with the group's top-ranked candidates (#rank)"
                + ("; under a panel whose candidates include the truncated series, the slip u(t) of that series and "
                   "of the exact solution of the same law (dotted: where the series' slip crosses zero)"
                   if any(v.series for v in shown) else "") + "."
                + (f" The first {len(shown)} of {len(views)} groups; each group's page (under 'Dataset groups') "
                   "draws its own." if len(shown) < len(views) else ""),
                lambda: figures.group_figure(shown, view_title(shown)))
        sec.p(_side(views))
    _unfitted(sec, c.answers)
    _accuracy_table(sec, c)
    return sec


#: Panels the first screen's figure draws at most (three rows of five): a comparison of many groups shows the first
#: of them there, and each group's page draws its own.
MAX_PANELS = 15


def _side(views) -> str:
    """The sentences beside the figure; the paper's story heads them only where the paper's data show it."""
    story = [v for v in views if v.series is not None and v.series.t_cross is not None
             and v.dataset.provenance.seed_paper and spin_falls(v.dataset)]
    head = "**Why the paper's spin falls.** " if story else "**What the data show.** "
    return head + " ".join(describe(v) for v in views)


def _accuracy_table(sec: Section, c) -> None:
    """What accuracy costs per law and dataset, folded under one line below the verdict table."""
    rows = list(getattr(c, "accuracy", ()))
    if not rows:
        return
    labels = list(dict.fromkeys(r.label for r in rows if r.status == "ok" and not r.reference))
    table = []
    for (ds, law) in dict.fromkeys((r.dataset, r.law) for r in rows):
        mine = [r for r in rows if (r.dataset, r.law) == (ds, law)]
        ref = next((r for r in mine if r.reference), None)
        if ref is None:
            table.append([ds, law, f"{mine[0].status}: {mine[0].reason}"] + [""] * len(labels))
            continue
        by = {r.label: r for r in mine}
        cells = []
        for label in labels:
            r = by.get(label)
            cells.append("" if r is None else (f"{r.status}: {r.reason}" if r.status != "ok" else
                                               f"{_sigmas(r.error_sigma)}, {sig(r.time_ratio, 2)}×"))
        table.append([ds, law, f"{ref.label}, {_micro(ref.time_s)}"] + cells)
    sec.more_table("What accuracy costs, per law and dataset: each solver's error against the most accurate one "
                   "(in noise σ; stated precisions for stated numbers) and its time as a multiple of that one's, at "
                   "the law's fitted parameters",
                   ["dataset", "law", "reference (CPU per prediction)"] + [f"{label}: error, time" for label in labels],
                   table)


def _sigmas(x: float) -> str:
    return "0" if x == 0 else f"{x:.2g}σ" if math.isfinite(x) else ""


def _micro(t: float) -> str:
    return f"{t * 1e6:.3g} µs" if t < 1e-3 else f"{t * 1e3:.3g} ms" if t < 1 else f"{t:.3g} s"
