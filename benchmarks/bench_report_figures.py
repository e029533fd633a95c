"""CPU seconds of drawing the default report's figures with the report's own Agg renderer and tick windows
(``report.figures.agg``: each text measured and laid out once, each glyph rendered once per quarter-pixel phase
of its origin; ``report.figures.ticks``: each axis' ticks worked out once per draw or measurement) against
matplotlib's (``FigureCanvasAgg``, ticks worked out each time they are asked for) and against the report's with
glyph origins on matplotlib's 1/64-pixel grid (``agg.STEP = 1``), in turns in one process: the minimum over the
rounds, by kind (the file name up to its first '-' or '.'), the glyph bitmaps FreeType rendered for the report's
renderer, and whether the PNG bytes of the latter two are the same.

    python benchmarks/bench_report_figures.py [ROUNDS]      (default 3)

The comparison (``frictionlab.compare()``: every built-in dataset and measured record present, no bootstrap) is
run once; its report's figures are drawn as ``write_report`` draws them (a figure shared by pages once), each
round from fresh canvases (``base.release``).
"""
from __future__ import annotations

import collections
import contextlib
import gc
import sys
import time


def main(rounds: int = 3) -> None:
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    import frictionlab
    from frictionlab import report
    from frictionlab.report.figures import agg, base, ticks

    c = frictionlab.compare()
    figs, keys = [], set()
    for page in report._pages(c, {}):
        for sec in page[1]:
            for f in sec.figures:
                if f.key is None or f.key not in keys:
                    keys.add(f.key)
                    figs.append(f)
    own = agg.Canvas, ticks.same, agg.STEP
    ways = {"matplotlib's": (FigureCanvasAgg, lambda fig: contextlib.nullcontext(), own[2]), "the report's": own,
            "the report's at 1/64 pixel": (*own[:2], 1)}
    for f in figs:  # imports and font caches
        f.draw()
    base.release()
    gc.freeze()
    cpu, pngs, rendered = {w: [] for w in ways}, {}, {}
    try:
        for _ in range(rounds):
            for way, (canvas, window, step) in ways.items():
                agg.Canvas, ticks.same, agg.STEP = canvas, window, step
                t = collections.Counter()
                drawn = []
                for f in figs:
                    c0 = time.process_time()
                    drawn.append(f.draw())
                    t[f.name.replace(".", "-").split("-")[0]] += time.process_time() - c0
                rendered[way] = len(vars(agg._KEPT).get("glyphs", ()))
                base.release()
                cpu[way].append(t)
                pngs[way] = drawn
    finally:
        agg.Canvas, ticks.same, agg.STEP = own
    best = {w: min(ts, key=lambda t: sum(t.values())) for w, ts in cpu.items()}
    print(f"{len(figs)} figures, {rounds} rounds; CPU s, the least of the rounds:")
    for way, t in best.items():
        print(f"  {way} renderer and ticks: {sum(t.values()):.2f} (" +
              ", ".join(f"{k} {v:.2f}" for k, v in sorted(t.items(), key=lambda kv: -kv[1])) + ")")
        print("    rounds: " + ", ".join(f"{sum(t.values()):.2f}" for t in cpu[way]) +
              (f"; glyph bitmaps rendered: {rendered[way]}" if rendered[way] else ""))
    plain, fast, fine = (sum(best[w].values()) for w in ways)
    print(f"matplotlib's / the report's: {plain / fast:.2f}; "
          f"the report's at 1/64 pixel / at 1/4 pixel: {fine / fast:.2f}")
    same = sum(a == b for a, b in zip(pngs["matplotlib's"], pngs["the report's at 1/64 pixel"]))
    print(f"PNG bytes at 1/64 pixel the same as matplotlib's: {same} of {len(figs)}")


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:2]))
