"""The comparison report: one folder, written whole or not at all.

``write_report(comparison, out, force=False, progress=None)`` writes, through ``core.outfolder.atomic_dir`` (with
``force``, what the user added to an earlier report folder is kept):
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

import collections
import json
import os
import threading
from collections.abc import Callable
from concurrent.futures import as_completed
from typing import TYPE_CHECKING
from pathlib import Path

import attrs

from ..core.arguments import check_type
from ..core.errors import OutputError
from ..core.outfolder import atomic_dir
from ..core.inputs import check_apart
from ..core.workers import long_run_gc
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
from ..core.fpstate import with_own_errstate

if TYPE_CHECKING:  # annotations only
    from dask.distributed import Client

    from ..pipeline.comparison import Comparison

TITLE = "frictionlab: friction laws compared"

#: The report's sections, in order; the first screen first.
SECTIONS = (first_screen, summary, datasets, ranking, bootstrap, fits, rebound, equivalence, transfer, derivation,
            tolerance, identifiability, method)
#: The index page's sections when the report has a page per group (``pages``); the list of groups goes before
#: the last.
INDEX_SECTIONS = (first_screen, summary, method)

__all__ = ["SCHEMA", "SECTIONS", "Context", "Section", "build", "clean", "fit_json", "results_json",
           "tolerance_verdicts", "write_report"]


@attrs.define
class Context:
    """What a section's ``build`` gets: the Comparison, a dict for numbers results.json carries, and whether the
    page is one group's page of a report in pages (``report.pages``)."""

    c: object
    json: dict = attrs.field(factory=dict)
    group_page: bool = False


def build(c, modules=SECTIONS, group_page: bool = False) -> tuple[list[Section], dict]:
    """The sections of the report (figures not drawn yet) and the extra numbers for results.json."""
    ctx = Context(c, group_page=group_page)
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


#: Figures drawn by one task on a cluster: a few per task (fewer round trips, closures pickled together)
DRAW_BATCH = 4


def _drawn(figs, jobs: int, client=None):
    """(index, PNG bytes) of every figure of the iterable ``figs``, in the order they finish; ``figs`` is used up
    before the first comes back. On ``jobs`` forked workers when jobs > 1, or on a dask.distributed ``client``'s
    workers in tasks of DRAW_BATCH figures, each sent as soon as its figures are built (the draw closures travel
    by cloudpickle), so that the workers draw while the next pages are built."""
    from ..core.cluster import executor
    from ..core.workers import process_pool

    if client is not None:
        from .figures import _plt

        with executor(1, client, "report", warm=_plt) as ex:  # pyplot imported once per worker
            futures = {ex.submit(_draw_each, [f.draw for f in batch]): first
                       for first, batch in _batches(figs, DRAW_BATCH)}
            for fut in as_completed(futures):
                for k, png in enumerate(fut.result()):
                    yield futures[fut] + k, png
        return
    figs = list(figs)
    if jobs <= 1 or len(figs) <= 1:
        from ..core.signals import kept_signals
        from .figures.base import release

        try:
            for i, f in enumerate(figs):
                with kept_signals():  # a law plugin drawn here does not keep SIGINT, SIGTERM or SIGHUP
                    png = f.draw()
                yield i, png
        finally:
            release()  # the canvases kept for the next figure of a kind (figures.base.subplots)
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


def _draw_each(draws) -> list[bytes]:
    return [draw() for draw in draws]


def _batches(items, n: int):
    """(index of its first item, list of up to ``n`` items) of consecutive items of the iterable ``items``."""
    batch, first = [], 0
    for i, item in enumerate(items):
        if not batch:
            first = i
        batch.append(item)
        if len(batch) == n:
            yield first, batch
            batch = []
    if batch:
        yield first, batch


@with_own_errstate
def write_report(c: Comparison, out: str | os.PathLike, force: bool = False,
                 progress: Callable[[int, int, str], None] | None = None, jobs: int = 1,
                 client: Client | None = None) -> Path:
    """Write the report of a comparison into a folder, whole or not at all.

    The folder holds ``report.html`` (self-contained), ``report.md``, ``figures/``, ``ranking.csv`` and
    ``results.json``. A comparison of more than ``pages.GROUP_PAGES_AT`` dataset groups is written as an index
    (every group's verdict, the summary, a link per group) and one page per group (``groups/GROUP.html``).

    Parameters
    ----------
    c : Comparison
        What `compare` returned.
    out : str or os.PathLike
        The report folder.
    force : bool, default False
        Replace an existing folder (otherwise an existing folder is an error).
    progress : callable, optional
        ``progress(done, total, label)``, called after each figure and file.
    jobs : int, default 1
        Worker processes drawing the figures (the same PNG bytes as one process draws).
    client : distributed.Client, optional
        A Dask client whose workers draw the figures instead.

    Returns
    -------
    pathlib.Path
        The report folder.

    Raises
    ------
    OutputError
        ``out`` exists and ``force`` is False, it lies inside a dataset it reports on, or cannot be written.
    """
    from ..pipeline.comparison import Comparison

    check_type(c, Comparison, "write_report: c", "a Comparison (what frictionlab.compare returns)")
    check_type(out, (str, os.PathLike), "write_report: out", "a folder path")
    check_apart(out, [p for d in c.datasets if d.path is not None for p in (d.path, d.path.with_suffix(".csv"))])
    out = Path(out)
    if out.exists() and not force:  # said in Python's terms; the command line checks before its work
        raise OutputError(f"{out}: the folder exists; pass force=True to replace it, or choose another folder")
    # what is alive before (the comparison) frozen meanwhile: drawing makes many short-lived objects, and each
    # full collection would walk the comparison too (about 0.2 of the default report's 4 CPU s)
    with atomic_dir(out, force=force) as tmp, long_run_gc():
        built, figs, extra = [], [], {}
        same: dict = {}  # a figure's key -> the index in figs of the first figure drawn with it
        copies = collections.defaultdict(list)  # index in figs -> (page, figure) of the others with its key

        def figures():  # page by page as each is built: a cluster draws a page's figures while the next is built
            for page in _pages(c, extra):
                built.append(page)
                for sec in page[1]:
                    for f in sec.figures:
                        if f.key is not None and f.key in same:  # drawn once for every page that shows it
                            copies[same[f.key]].append((len(built) - 1, f))
                            continue
                        if f.key is not None:
                            same[f.key] = len(figs)
                        figs.append((len(built) - 1, f))
                        yield f
            missing.update(k for k, _ in figs)
            missing.update(k for more in copies.values() for k, _ in more)
            _write_texts(tmp, c, built, extra)  # every page built: while a pool or cluster draws the last figures

        images, missing = {}, collections.Counter()  # missing: per page, how many of its figures are still to come
        for done, (i, png) in enumerate(_drawn(figures(), jobs, client), 1):  # every page is built by now
            for k, f in [figs[i]] + copies[i]:
                figdir = built[k][2]
                images[(figdir, f.name)] = png
                (tmp / figdir).mkdir(parents=True, exist_ok=True)
                (tmp / figdir / f.name).write_bytes(png)
                missing[k] -= 1
                if not missing[k]:  # the page's last figure: its HTML now, while the others are drawn
                    _write_html(tmp, built[k], images)
            f = figs[i][1]
            if progress:
                progress(done, len(figs) + 1, f"figure {f.name}")
        (tmp / "figures").mkdir(exist_ok=True)
        if progress:
            progress(len(figs) + 1, len(figs) + 1, "report.md, report.html, ranking.csv, results.json")
    return out


def _title(path: str) -> str:
    return TITLE if path == "report" else f"{TITLE}: {path.split('/', 1)[1]}"


def _write_html(tmp: Path, page: tuple, images: dict) -> None:
    """One page's HTML, which carries its figures (``images``: PNG bytes by figure folder and name)."""
    path, sections, figdir = page
    own = {f.name: images[(figdir, f.name)] for s in sections for f in s.figures}  # in page order
    (tmp / path).with_suffix(".html").write_text(html_page(_title(path), sections, own), encoding="utf-8")


def _write_texts(tmp: Path, c, built: list, extra: dict) -> None:
    """What needs no figure's bytes: each page's Markdown (its figures linked), the HTML of a page without
    figures, ranking.csv and results.json."""
    for path, sections, figdir in built:
        page = tmp / path
        page.parent.mkdir(parents=True, exist_ok=True)
        up = "../" * path.count("/")
        page.with_suffix(".md").write_text(markdown(_title(path), sections, up + figdir), encoding="utf-8")
        if not any(s.figures for s in sections):
            _write_html(tmp, (path, sections, figdir), {})
    (tmp / "ranking.csv").write_text(ranking_csv(c), encoding="utf-8")
    (tmp / "results.json").write_text(json.dumps(results_json(c, extra), indent=1, allow_nan=False),
                                      encoding="utf-8")


def _pages(c, extra: dict):
    """(page path without suffix, sections, figure folder) of each page, as it is built: one page, or (many
    groups) the index and a page per group; ``extra`` gets the numbers for results.json."""
    from . import pages

    if len(pages.groups_of(c)) <= pages.GROUP_PAGES_AT:
        sections, more = build(c)
        extra.update(more)
        yield "report", sections, "figures"
        return
    for path, cc, modules, figdir, groups in pages.pages(c, SECTIONS, INDEX_SECTIONS):
        sections, more = build(cc, modules, group_page=not groups)
        if groups:
            sections.insert(len(sections) - 1, pages.index_section(groups))
        elif sections:  # a group's page: the way back to the index first
            sections[0].blocks.insert(0, ("links", [("all dataset groups (the index)", "../report.html")]))
        for k, v in more.items():  # one level deep: numbers per dataset from every page
            extra[k] = {**extra.get(k, {}), **v} if isinstance(v, dict) else v
        yield path, sections, figdir
