"""'Datasets and provenance': every dataset, how it was made, and whether it was fitted."""
from __future__ import annotations

from .doc import Section
from .text import PROVENANCE_WORDS

TITLE = "Datasets and provenance"


def build(ctx) -> Section:
    c = ctx.c
    sec = Section(TITLE)
    rows = []
    for d in c.datasets:
        pv = d.provenance
        truth = ", ".join(f"{k} = {v}" for k, v in pv.truth.items()) if pv.truth else ""
        status = "fitted" if d.name not in c.skipped_datasets else f"not fitted: {c.skipped_datasets[d.name]}"
        how = "; ".join(x for x in (pv.method, f"regenerate with `{pv.command}`" if pv.command else "",
                                    f"seed {pv.seed}" if pv.seed is not None else "") if x)
        rows.append([d.name, d.kind, d.observable, len(d), PROVENANCE_WORDS.get(pv.kind, pv.kind), pv.source, how,
                     truth, status])
    sec.table(["dataset", "kind", "observable", "points", "provenance", "source", "how it was made",
               "generating truth", "status"], rows)
    return sec
