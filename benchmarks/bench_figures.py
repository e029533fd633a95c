"""CPU seconds a dataset of the report's four per-dataset figures (fit, force, discrimination, equivalence) of n
small synthetic impacts, drawn on kept canvases (``report.figures.base.subplots``: the next figure of a kind
reuses the last one's axes, emptied) against a fresh canvas for every figure, in turns in one process (the
minimum over the rounds; load on the machine slows both alike). The comparison is run once, without the
bootstrap, which draws no figure of these kinds.

    python benchmarks/bench_figures.py [N [ROUNDS]]      (default 10 datasets, 5 rounds)
"""
from __future__ import annotations

import collections
import gc
import sys
import tempfile
import time
from pathlib import Path

KINDS = ("fit", "force", "discrimination", "equivalence")


def main(n: int = 10, rounds: int = 5) -> None:
    sys.path.insert(0, str(Path(__file__).parent))
    import bench_many

    from frictionlab import compare, report
    from frictionlab.report.figures import base

    with tempfile.TemporaryDirectory() as tmp:
        c = compare(datasets=[str(p) for p in bench_many.make(n, Path(tmp))])
        figs = [f for page in report._pages(c, {}) for sec in page[1] for f in sec.figures
                if f.name.split("-")[0] in KINDS]
    for f in figs[:4]:  # imports and font caches
        f.draw()
    gc.freeze()
    ways = {"fresh canvas": base.release, "kept canvas": lambda: None}  # what runs before each figure
    cpu = {way: [] for way in ways}
    for _ in range(rounds):
        for way, before in ways.items():
            t = collections.Counter()
            for f in figs:
                before()
                c0 = time.process_time()
                f.draw()
                t[f.name.split("-")[0]] += time.process_time() - c0
            base.release()
            cpu[way].append(t)
    for way, ts in cpu.items():
        best = min(ts, key=lambda t: sum(t.values()))
        print(f"{way}: {sum(best.values()) / n:.3f} CPU s a dataset (" +
              ", ".join(f"{k} {best[k] / n:.3f}" for k in KINDS) + ")")
    fresh, kept = (min(sum(t.values()) for t in cpu[w]) for w in ways)
    print(f"fresh / kept: {fresh / kept:.2f}")


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:3]))
