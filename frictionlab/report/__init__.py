"""The comparison report: one folder, written whole or not at all.

``write_report(comparison, out, force=False, progress=None)`` writes, through ``io.atomic_dir``:
``report.md``; a self-contained ``report.html`` (figures embedded, a small inline script sorts
tables); ``figures/*.png``; ``ranking.csv``; ``results.json`` (schema in ``results.py``).

Layout: the first screen (``first_screen.py``: the verdict table from ``Comparison.answers`` and
the figure of the central finding) is shown open; every other section is collapsible. Each
section is one module here with ``TITLE`` and ``build(ctx) -> Section | list[Section] | None``;
``ctx.c`` is the Comparison and ``ctx.json`` collects numbers a section computes for
results.json. ``SECTIONS`` below fixes their order. Sections describe content only
(``doc.Section``: ``p``, ``warn``, ``items``, ``table``, ``h3``, ``fig(name, caption, draw)``);
``render.py`` and ``templates/`` turn them into Markdown and HTML, and figures are drawn once,
when the report is written.

To add a section: write ``frictionlab/report/mysection.py``::

    from .doc import Section

    TITLE = "My section"

    def build(ctx):
        sec = Section(TITLE)
        sec.p("What it shows, in one sentence.")
        sec.table(["dataset", "value [unit]"], [[d.name, "1.23"] for d in ctx.c.fitted_datasets])
        return sec

and add ``mysection`` to ``SECTIONS`` at the place it belongs. Return None to leave it out.
"""
from __future__ import annotations

import json
import os
import threading
from concurrent.futures import as_completed
from pathlib import Path

import attrs

from ..core.arguments import check_type
from ..core.errors import OutputError
from ..core.files import atomic_dir
from ..core.inputs import check_apart
from . import (
    bootstrap,
    datasets,
    derivation,
    equivalence,
    first_screen,
    fits,
    identifiability,
    method,
    ranking,
    rebound,
    summary,
    tolerance,
    transfer,
)
from .doc import Section
from .render import html_page, markdown
from .results import SCHEMA, clean, fit_json, ranking_csv, results_json
from .tolerance import tolerance_verdicts

TITLE = "frictionlab: friction laws compared"

#: The report's sections, in order; the first screen first.
SECTIONS = (first_screen, summary, datasets, ranking, bootstrap, fits, rebound, equivalence, transfer, derivation,
            tolerance, identifiability, method)

__all__ = ["SCHEMA", "SECTIONS", "Context", "Section", "build", "clean", "fit_json", "results_json",
           "tolerance_verdicts", "write_report"]


@attrs.define
class Context:
    """What a section's ``build`` gets: the Comparison, and a dict for numbers results.json carries."""

    c: object
    json: dict = attrs.field(factory=dict)


def build(c, modules=SECTIONS) -> tuple[list[Section], dict]:
    """The sections of the report (figures not drawn yet) and the extra numbers for results.json."""
    ctx = Context(c)
    out: list[Section] = []
    for m in modules:
        got = m.build(ctx)
        if got is None:
            continue
        out.extend(got if isinstance(got, list) else [got])
    return out, ctx.json


#: The figures being drawn, for forked workers: their draw functions are closures, which do not pickle.
_FIGURES: list = []


def _draw(i: int) -> bytes:
    return _FIGURES[i].draw()


_DRAWING = threading.Lock()  # one report at a time hands its figures to forked workers through _FIGURES


def _drawn(figs, jobs: int):
    """(index, PNG bytes) of every figure, in the order they finish: on ``jobs`` forked workers when jobs > 1."""
    from ..core.workers import process_pool

    if jobs <= 1 or len(figs) <= 1:
        for i, f in enumerate(figs):
            yield i, f.draw()
        return
    from .figures import _plt

    _plt()  # pyplot imported once here, before the workers fork, instead of once in each
    with _DRAWING:
        _FIGURES[:] = figs
        try:
            with process_pool(jobs, "report: drawing the figures") as pool:
                if pool is None:  # no fork on this platform
                    for i, f in enumerate(figs):
                        yield i, f.draw()
                    return
                futures = {pool.submit(_draw, i): i for i in range(len(figs))}
                for fut in as_completed(futures):
                    yield futures[fut], fut.result()
        finally:
            _FIGURES.clear()


def write_report(c, out, force: bool = False, progress=None, jobs: int = 1) -> Path:
    """Write the report folder ``out`` whole or not at all; an existing folder is replaced only with force=True.

    progress(done, total, label), if given, is called after each figure and file. jobs: worker
    processes drawing the figures (the same PNG bytes as one process draws).
    """
    from ..pipeline.comparison import Comparison

    check_type(c, Comparison, "write_report: c", "a Comparison (what frictionlab.compare returns)")
    check_type(out, (str, os.PathLike), "write_report: out", "a folder path")
    check_apart(out, [p for d in c.datasets if d.path is not None for p in (d.path, d.path.with_suffix(".csv"))])
    out = Path(out)
    if out.exists() and not force:  # said in Python's terms; the command line checks before its work
        raise OutputError(f"{out}: the folder exists; pass force=True to replace it, or choose another folder")
    with atomic_dir(out, force=force) as tmp:
        sections, extra = build(c)
        figs = [f for s in sections for f in s.figures]
        total, images = len(figs) + 1, {}
        (tmp / "figures").mkdir()
        for done, (i, png) in enumerate(_drawn(figs, jobs), 1):
            images[figs[i].name] = png
            (tmp / "figures" / figs[i].name).write_bytes(png)
            if progress:
                progress(done, total, f"figure {figs[i].name}")
        images = {f.name: images[f.name] for f in figs}  # in report order
        (tmp / "report.md").write_text(markdown(TITLE, sections), encoding="utf-8")
        (tmp / "report.html").write_text(html_page(TITLE, sections, images), encoding="utf-8")
        (tmp / "ranking.csv").write_text(ranking_csv(c), encoding="utf-8")
        (tmp / "results.json").write_text(json.dumps(results_json(c, extra), indent=1, allow_nan=False),
                                          encoding="utf-8")
        if progress:
            progress(total, total, "report.md, report.html, ranking.csv, results.json")
    return out
