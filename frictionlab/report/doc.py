"""The report's building blocks: a Section holds paragraphs, lists, tables and figures.

Sections only describe content; ``render`` turns them into Markdown and HTML through the
templates, and ``write_report`` draws each figure once (a figure is a name, a caption and a
function returning PNG bytes, called only when the report is written).
"""
from __future__ import annotations

import re
from collections.abc import Callable

import attrs

#: A table cell that starts like a number ("1.2e+06 ± 3e4 Pa s/m", "-0.5", "#1", "12%") is right-aligned.
_NUMERIC = re.compile(r"^\s*[#≈]?[-+−]?(\d|\.\d|inf\b)")


def is_numeric(cell: str) -> bool:
    return bool(_NUMERIC.match(cell))


@attrs.define
class Table:
    """Headers (with units in brackets) and rows of strings; numeric columns are right-aligned."""

    headers: list[str]
    rows: list[list[str]]

    @property
    def short_names(self) -> bool:
        """The first column holds short names (kept on one line in HTML)."""
        return all(len(r[0]) <= 30 for r in self.rows if r)

    @property
    def numeric(self) -> list[bool]:
        """Per column: every non-empty cell (ignoring '–' placeholders) is a number."""
        out = []
        for j in range(len(self.headers)):
            cells = [r[j] for r in self.rows if j < len(r) and r[j] not in ("", "–", "—")]
            out.append(bool(cells) and all(is_numeric(c) for c in cells))
        return out


@attrs.define
class Figure:
    """A PNG figure drawn on demand: ``draw()`` returns its bytes (called once, when the report is written)."""

    name: str
    caption: str
    draw: Callable[[], bytes]
    side: str = ""  # text shown beside the figure in HTML (before it in Markdown)
    key: object = None  # figures of one report with one (hashable) key are the same picture: drawn once


@attrs.define
class Section:
    """One part of the report. ``open`` sections are shown in full; the others are collapsible in HTML."""

    title: str
    blocks: list = attrs.field(factory=list)  # (kind, payload) with kind h3 | p | warn | ul | more | moretable | table | fig
    open: bool = False

    @property
    def anchor(self) -> str:
        return anchor(self.title)

    def h3(self, text: str):
        self.blocks.append(("h3", text))

    def p(self, text: str):
        self.blocks.append(("p", text))

    def warn(self, text: str):
        self.blocks.append(("warn", text))

    def items(self, items):
        items = list(items)
        if items:
            self.blocks.append(("ul", items))

    def more(self, summary: str, items):
        """A list folded under one line ``summary`` in HTML (opened by a click), a plain list in Markdown."""
        items = list(items)
        if items:
            self.blocks.append(("more", (summary, items)))

    def more_table(self, summary: str, headers, rows):
        """A table folded under one line ``summary`` in HTML (opened by a click); in Markdown a bold line and the table."""
        rows = [[("" if c is None else str(c)) for c in r] for r in rows]
        if rows:
            self.blocks.append(("moretable", (summary, Table(list(headers), rows))))

    def table(self, headers, rows):
        rows = [[("" if c is None else str(c)) for c in r] for r in rows]
        if rows:
            self.blocks.append(("table", Table(list(headers), rows)))

    def links(self, items):
        """A list of (label, relative address) links to other pages of the report."""
        items = list(items)
        if items:
            self.blocks.append(("links", items))

    def fig(self, name: str, caption: str, draw: Callable[[], bytes], side: str = "", key: object = None):
        """A figure file ``name`` (characters other than letters, digits, '.', '-' and '_' become '_'),
        optionally with a text ``side`` shown beside it; ``key``: one picture on several pages of a report
        (the same key) is drawn once."""
        self.blocks.append(("fig", Figure(re.sub(r"[^A-Za-z0-9._-]", "_", name), caption, draw, side, key)))

    @property
    def figures(self) -> list[Figure]:
        return [b[1] for b in self.blocks if b[0] == "fig"]


def anchor(text: str) -> str:
    return "".join(c if c.isalnum() else "-" for c in text.lower()).strip("-")
