"""CPU seconds of drawing the default report's figures (matplotlib's Agg canvas, PNG written by Pillow), by kind, on
the kept canvases (``base.subplots``: each kind of figure drawn again on its emptied canvas) and each on a fresh
canvas, in turns in one process: the least over the rounds, and whether the PNG bytes are the same both ways.

    python benchmarks/bench_report_figures.py [ROUNDS]      (default 3)

The comparison (``frictionlab.compare()``: every built-in dataset and measured record present, no bootstrap) is
run once; its report's figures are drawn as ``write_report`` draws them (a figure shared by pages once).
"""
from __future__ import annotations

import collections
import gc
import sys
import time


def main(rounds: int = 3) -> None:
    import frictionlab
    from frictionlab import report
    from frictionlab.report.figures import base

    c = frictionlab.compare(bootstrap=0)
    figs, keys = [], set()
    for page in report._pages(c, {}):
        for sec in page[1]:
            for f in sec.figures:
                if f.key is None or f.key not in keys:
                    keys.add(f.key)
                    figs.append(f)
    for f in figs:  # imports and font caches
        f.draw()
    base.release()
    gc.freeze()
    cpu, pngs = {"kept canvases": [], "fresh canvases": []}, {}
    for _ in range(rounds):
        for way in cpu:
            t, drawn = collections.Counter(), []
            for f in figs:
                if way == "fresh canvases":
                    base.release()
                c0 = time.process_time()
                drawn.append(f.draw())
                t[f.name.replace(".", "-").split("-")[0]] += time.process_time() - c0
            base.release()
            cpu[way].append(t)
            pngs[way] = drawn
    print(f"{len(figs)} figures, {rounds} rounds; CPU s, the least of the rounds:")
    for way, ts in cpu.items():
        t = min(ts, key=lambda t: sum(t.values()))
        print(f"  {way}: {sum(t.values()):.2f} (" +
              ", ".join(f"{k} {v:.2f}" for k, v in sorted(t.items(), key=lambda kv: -kv[1])) + ")")
        print("    rounds: " + ", ".join(f"{sum(t.values()):.2f}" for t in ts))
    same = sum(a == b for a, b in zip(*pngs.values()))
    print(f"PNG bytes the same both ways: {same} of {len(figs)}; {sum(map(len, pngs['kept canvases'])) / 1e6:.2f} MB")


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:2]))
