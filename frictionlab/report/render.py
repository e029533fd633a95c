"""Markdown and self-contained HTML from Sections, through the jinja2 templates in ``templates/``.

Text in a Section may use **bold** and `code`; everything else is escaped: in HTML by jinja2's
autoescape (and every printed value stripped of control characters), in Markdown by ``md_text`` (entities for < > &, brackets escaped, lines joined, control
characters dropped): a dataset name or description never becomes raw HTML, a link, an image, a
heading or a table in either file.
"""
from __future__ import annotations

import base64
import html
import re
from functools import lru_cache

from markupsafe import Markup

from ..core.terminal import inert
from .doc import is_numeric


def inline_html(text: str) -> Markup:
    """Escape, then render **bold** and `code` as the Markdown does."""
    s = html.escape(str(text), quote=True)
    s = re.sub(r"\*\*(.+?)\*\*", r"<b>\1</b>", s)
    return Markup(re.sub(r"`(.+?)`", r"<code>\1</code>", s))


_NUMBER = r"[-+−]?(?:\d+\.?\d*|\.\d+)(?:e[-+]?\d+)?"
#: The number a numeric cell starts with, and its standard error: '0.0114 ± 0.0012'.
_VALUE = re.compile(rf"^\s*[#≈]?{_NUMBER}(?: ± {_NUMBER})?")


def num_html(text: str) -> Markup:
    """A numeric cell: the number it starts with (and its ± error) in a ``span.v`` that the page's style keeps on
    one line; the rest of the cell (a unit, a note in brackets) free to wrap."""
    text = str(text)
    m = _VALUE.match(text)
    if not m:
        return inline_html(text)
    return Markup('<span class="v">') + inline_html(m.group(0)) + Markup("</span>") + inline_html(text[m.end():])


#: What could open a block at the start of a line: a heading, a list item, a numbered item, a rule,
#: a fence (a quote '>' is already an entity).
_BLOCK_START = re.compile(r"^(\d+)?(#|[-+*](?=\s)|[.)](?=\s|$)|```|~~~)")


def md_text(text: str) -> str:
    """Text for Markdown, inert: control characters dropped; lines joined (a multi-line description
    cannot start a heading or a table); HTML specials as entities; backslashes and a ']' before '(',
    '[' or ':' escaped (no link, image or reference can open: no remote image, no javascript: link);
    a leading block marker escaped.
    ``**bold**`` and ```code``` still work, as in the HTML."""
    return _BLOCK_START.sub(lambda m: (m.group(1) or "") + "\\" + m.group(2), _md_inline(text))


def _md_inline(text: str) -> str:
    s = re.sub(r"\s*\n\s*", " ", inert(str(text))).strip()
    s = html.escape(s, quote=False).replace("\\", "\\\\")
    return re.sub(r"\](?=[(\[:])", r"\\]", s)  # '](', '][', ']:' escaped: no link, image or reference opens


def md_cell(text: str) -> str:
    return _md_inline(text).replace("|", "\\|")


def sort_key(cell: str) -> str:
    """The number a cell starts with (for sorting), else the cell itself."""
    m = re.match(rf"^\s*[#≈]?({_NUMBER})", cell)
    return m.group(1).replace("−", "-") if m else cell.lower()


def b64(data: bytes) -> str:
    return base64.b64encode(data).decode("ascii")


def _inert_value(value):
    """Every value a template prints, without control characters or escape sequences (``cat report.html``
    in a terminal must not act on a description's OSC or CSI sequence); escaped Markup stays Markup."""
    if isinstance(value, Markup):
        return Markup(inert(value))
    return inert(value) if isinstance(value, str) else value


@lru_cache(maxsize=1)
def environment():
    import jinja2

    env = jinja2.Environment(loader=jinja2.PackageLoader("frictionlab.report", "templates"),
                             autoescape=jinja2.select_autoescape(["html", "html.j2"]),
                             trim_blocks=True, lstrip_blocks=True, keep_trailing_newline=True,
                             finalize=_inert_value)
    env.filters.update(inline=inline_html, num=num_html, md=md_text, mdcell=md_cell, sortkey=sort_key, b64=b64)
    env.tests["numeric"] = is_numeric
    return env


def markdown(title: str, sections, figdir: str = "figures") -> str:
    """The page's Markdown; figures are linked from ``figdir`` (relative to the page)."""
    return environment().get_template("report.md.j2").render(title=title, sections=sections, figdir=figdir)


def html_page(title: str, sections, images: dict[str, bytes]) -> str:
    return environment().get_template("report.html.j2").render(title=title, sections=sections, images=images)
