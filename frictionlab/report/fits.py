"""'Fits': per dataset the fits of every law, their parameters, warnings and notes, and known truth."""
from __future__ import annotations

import re

from ..core.display import param_cells, param_text
from ..core.errors import FrictionLabError
from ..core.units import to_si
from ..inference.diagnostics.identifiability import AT_BOUND_MEANING
from ..physics.registry import get_law
from . import figures
from .doc import Section
from .text import micro

TITLE = "Fits"


def truth_check(d, c) -> str:
    """For data generated with a known law: where that law ranks and how far its fit lands from the truth."""
    truth = dict(d.provenance.truth or {})
    law = truth.pop("law", None)
    if not law or law not in c.laws:
        return ""
    rows = [r for r in c.ranking if r.dataset == d.name and r.law == law and r.rank]
    parts = []
    for r in rows:
        f = c.fit_for(d.name, law, r.solver)
        found = []
        for name, text in truth.items():
            p = f.params.get(name) if f else None
            if p is None or not p.vary:
                continue
            try:
                value = to_si(text, get_law(law).spec(name).unit, f"{d.name}: provenance.truth.{name}")
            except FrictionLabError:
                continue
            dev = f" ({(p.value - value) / p.stderr:+.1f}σ)" if p.stderr else ""
            found.append(f"{name}: true {param_text(value, None, p.unit, p.shown)}, fitted "
                         f"{param_text(p.value, p.stderr, p.unit, p.shown)}{dev}")
        parts.append(f"{law} [{r.solver}] ranks #{r.rank}" + (f" ({r.status} with {', '.join(r.tied_with)})"
                                                              if r.tied_with else "")
                     + ("; " + "; ".join(found) if found else ""))
    if not parts:
        return ""
    return f"**Known truth:** generated with {law}. " + ". ".join(parts) + "."


def reported_check(d, c) -> str:
    """Law parameters the source reports for this dataset, beside every fit of a law that has them."""
    parts = []
    for name, text in (d.reported or {}).items():
        for f in c.fits_on(d.name):
            p = f.params.get(name)
            if not f.ok or p is None or p.kind != "law" or not p.vary:
                continue
            try:
                value = to_si(text, get_law(f.law).spec(name).unit, f"{d.name}: reported.{name}")
            except FrictionLabError:
                continue
            parts.append(f"{name} reported {param_text(value, None, p.unit, p.shown)}, fitted by {f.law} [{f.solver}] "
                         f"{param_text(p.value, p.stderr, p.unit, p.shown)}")
    return ("**Reported by the source:** " + "; ".join(parts) + ".") if parts else ""


def flags_on(f, name: str) -> list[str]:
    """The verdict layer's plausibility flags of fit ``f`` (``FitResult.flags``, one sentence each) that
    name parameter ``name``."""
    return [t for t in getattr(f, "flags", ()) or () if re.search(rf"(?<![\w']){re.escape(name)}(?![\w'])", t)]


def param_rows(f) -> list[list[str]]:
    """One row per parameter of fit ``f``: value, error and unit in separate cells, its role, and a
    comment where the value means nothing (no effect, only a ratio determined) or is flagged implausible."""
    ratio_keys = {k for pair in f.identifiability.ratio_only for k in pair}
    rows = []
    for p in f.params.values():
        role, comment = ("fitted" if p.vary else (p.fixed_by or "held")), ""
        if p.vary and p.kind == "law" and p.key in ratio_keys:
            role, comment = "fitted", "arbitrary: only the ratio is determined"
        elif p.vary and p.name in f.identifiability.no_effect:
            comment = "arbitrary: it has no effect on these data (the value is where the optimizer stopped)"
        elif p.vary and p.at_bound:
            comment = (f"at its {p.at_bound} bound {param_text(p.bound, None, p.unit)}: not identifiable "
                       f"({AT_BOUND_MEANING})")
        elif p.vary and p.stderr is None:
            comment = f"no error bar: {f.identifiability.missing_stderr.get(p.name, 'see warnings')}"
        flagged = flags_on(f, p.name)
        if flagged:
            comment = "; ".join([comment] * bool(comment) + [f"implausible: {t}" for t in flagged])
        value, err, unit = param_cells(p.value, p.stderr if p.vary or p.kind == "derived" else None, p.unit, p.shown)
        rows.append([f"{f.law} [{f.solver}]", p.name, value, err, unit, role, comment])
    return rows


def fit_figure(sec: Section, d, fits, rows, caption: str) -> None:
    """The figure of every law's fit to dataset d with its residuals, in ``sec``: one picture wherever a page shows
    it (a group's page shows it on its first screen and among its fits)."""
    sec.fig(f"fit-{d.name}.png", caption, lambda: figures.fit_figure(d, fits, rows),
            key=("fit", id(d), tuple(id(f) for f in fits)))


def build(ctx) -> Section:
    c = ctx.c
    sec = Section(TITLE)
    fitted = c.fitted_datasets
    for d in fitted:
        fits = c.fits_on(d.name)
        rows = [r for r in c.ranking if r.dataset == d.name]
        sec.h3(d.name)
        if d.description:
            sec.p(micro(d.description))
        for check in (truth_check(d, c), reported_check(d, c)):
            if check:
                sec.p(check)
        if any(f.ok for f in fits):
            fit_figure(sec, d, fits, rows, f"{d.name}: data ({d.provenance.kind}) with each law's best fit, and residuals.")
            if "t" in d.columns and d.kind != "spring-slider":  # a slider's friction is mu N: the fit figure shows it
                sec.fig(f"force-{d.name}.png", f"{d.name}: friction force of each best fit.",
                        lambda d=d, fits=fits, rows=rows: figures.force_figure(d, fits, rows))
        prow = []
        for f in fits:
            if f.ok:
                prow += param_rows(f)
        sec.table(["law [solver]", "parameter", "value", "± standard error", "unit", "role", "comment"], prow)
        warns = [f"{f.law} [{f.solver}]: {w}" for f in fits if f.ok for w in f.identifiability.warnings]
        notes = [f"{f.law} [{f.solver}]: {n}" for f in fits if f.ok for n in f.notes]
        bad = [f"{f.law} [{f.solver}]: {f.status}: {f.reason}" for f in fits if not f.ok]
        flagged = [f"{f.law} [{f.solver}]: {t}" for f in fits if f.ok for t in getattr(f, "flags", ()) or ()]
        if flagged:
            sec.p("**Physically implausible (the verdict layer's flags):**")
            sec.items(flagged)
        if warns:
            sec.p("**Identifiability:**")
            sec.items(warns)
        if notes:
            sec.p("**Notes:**")
            sec.items(notes)
        if bad:
            sec.p("**Not fitted:**")
            sec.items(bad)
    return sec
