"""'Identifiability warnings': every fit whose parameters the data do not determine, and fits not made."""
from __future__ import annotations

from .doc import Section

TITLE = "Identifiability warnings"


def build(ctx) -> Section:
    c = ctx.c
    sec = Section(TITLE)
    allw = [f"{f.datasets[0]} — {f.law} [{f.solver}]: {f.identifiability.verdict}" for f in c.fits
            if f.ok and f.identifiability.warnings]
    if allw:
        sec.items(allw)
    else:
        sec.p("None: every fitted parameter is determined by its data.")
    failed = [f"{f.datasets[0]} — {f.law} [{f.solver}]: {f.status}: {f.reason}" for f in c.fits if not f.ok]
    if failed:
        sec.h3("Fits not made or failed")
        sec.items(failed)
    return sec
