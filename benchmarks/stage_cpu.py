"""Run the frictionlab command line in this process and write where its CPU time went, as JSON.

    python benchmarks/stage_cpu.py PARTS.json compare --out DIR --jobs 1 ...

What ``bench_compare.py`` runs instead of the bare command (a fresh process all the same): this process's
CPU seconds (user + system; with ``--jobs 1`` everything runs here) of the imports a comparison needs
(frictionlab, lmfit, scipy, matplotlib), of each stage of ``compare`` (``pipeline.runner``), of drawing the
report's figures (each figure's ``draw``, by kind: the file name up to its first '-' or '.') and of the whole
run; what is left is reading the datasets, planning, and writing the report's text.
"""
from __future__ import annotations

import json
import sys
import time
from collections import defaultdict


def cpu() -> float:
    return time.process_time()


def main() -> int:
    out, argv = sys.argv[1], sys.argv[2:]
    start = cpu()
    from frictionlab.cli import blas_one_thread

    blas_one_thread()  # as the console script does, before numpy is imported
    import lmfit  # noqa: F401  (imported by every comparison anyway; counted here as start-up)
    import matplotlib.pyplot  # noqa: F401
    import scipy.integrate  # noqa: F401

    from frictionlab import cli
    from frictionlab.pipeline import runner
    from frictionlab.report import doc

    parts = {"imports": cpu() - start, "stages": {}, "figures": defaultdict(float), "figure counts": defaultdict(int),
             "figure by name": defaultdict(float)}
    timed = runner._timed

    def stage(st, comparison, run):
        c0 = cpu()
        try:
            return timed(st, comparison, run)
        finally:
            parts["stages"][st.name] = parts["stages"].get(st.name, 0.0) + cpu() - c0

    runner._timed = stage
    fig = doc.Section.fig

    def counted(self, name, caption, draw, *args, **kw):
        kind = name.replace(".", "-").split("-")[0]

        def drawn():
            c0 = cpu()
            try:
                return draw()
            finally:
                parts["figures"][kind] += cpu() - c0
                parts["figure by name"][name] += cpu() - c0
                parts["figure counts"][kind] += 1
        return fig(self, name, caption, drawn, *args, **kw)

    doc.Section.fig = counted
    try:
        code = cli.main(argv)
    finally:
        parts["total"] = cpu() - start
        with open(out, "w") as fh:
            json.dump(parts, fh, indent=1)
    return code


if __name__ == "__main__":
    sys.exit(main())
