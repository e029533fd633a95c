"""'Datasets and provenance': every dataset, how it was made, and whether it was fitted."""
from __future__ import annotations

from .doc import Section
from .text import PROVENANCE_WORDS, micro

TITLE = "Datasets and provenance"


def build(ctx) -> Section:
    c = ctx.c
    sec = Section(TITLE)
    rows, notes = [], []
    for d in c.datasets:
        pv = d.provenance
        truth = ", ".join(f"{k} = {micro(str(v))}" for k, v in pv.truth.items() if not isinstance(v, dict)) if pv.truth else ""
        status = "fitted" if d.name not in c.skipped_datasets else f"not fitted: {c.skipped_datasets[d.name]}"
        how = "; ".join(x for x in (pv.method, f"regenerate with `{pv.command}`" if pv.command else "",
                                    f"seed {pv.seed}" if pv.seed is not None else "") if x)
        rows.append([d.name, d.kind, f"{d.observable} [{d.units.get(d.observable) or '-'}]", len(d),
                     PROVENANCE_WORDS.get(pv.kind, pv.kind), truth, status])
        notes.append(micro(f"**{d.name}**: {pv.source}. {how}"))
    sec.table(["dataset", "kind", "observable [unit]", "points", "provenance", "generating truth", "status"], rows)
    sec.p("Where each dataset comes from and how it was made:")
    sec.items(notes)
    return sec
