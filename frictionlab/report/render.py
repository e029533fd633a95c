"""Markdown and self-contained HTML from Sections, through the jinja2 templates in ``templates/``.

Text in a Section may use **bold** and `code`; everything else is escaped: in HTML by jinja2's
autoescape, in Markdown by turning < > & into entities (a dataset name or description never
becomes raw HTML in either file).
"""
from __future__ import annotations

import base64
import html
import re
from functools import lru_cache

from markupsafe import Markup

from .doc import is_numeric


def inline_html(text: str) -> Markup:
    """Escape, then render **bold** and `code` as the Markdown does."""
    s = html.escape(str(text), quote=True)
    s = re.sub(r"\*\*(.+?)\*\*", r"<b>\1</b>", s)
    return Markup(re.sub(r"`(.+?)`", r"<code>\1</code>", s))


def md_text(text: str) -> str:
    """Text for Markdown: HTML specials as entities, newlines kept."""
    return html.escape(str(text), quote=False)


def md_cell(text: str) -> str:
    return md_text(text).replace("|", "\\|").replace("\n", " ")


def sort_key(cell: str) -> str:
    """The number a cell starts with (for sorting), else the cell itself."""
    m = re.match(r"^\s*[#≈]?([-+−]?(?:\d+\.?\d*|\.\d+)(?:e[-+]?\d+)?)", cell)
    return m.group(1).replace("−", "-") if m else cell.lower()


def b64(data: bytes) -> str:
    return base64.b64encode(data).decode("ascii")


@lru_cache(maxsize=1)
def environment():
    import jinja2

    env = jinja2.Environment(loader=jinja2.PackageLoader("frictionlab.report", "templates"),
                             autoescape=jinja2.select_autoescape(["html", "html.j2"]),
                             trim_blocks=True, lstrip_blocks=True, keep_trailing_newline=True)
    env.filters.update(inline=inline_html, md=md_text, mdcell=md_cell, sortkey=sort_key, b64=b64)
    env.tests["numeric"] = is_numeric
    return env


def markdown(title: str, sections, figdir: str = "figures") -> str:
    """The page's Markdown; figures are linked from ``figdir`` (relative to the page)."""
    return environment().get_template("report.md.j2").render(title=title, sections=sections, figdir=figdir)


def html_page(title: str, sections, images: dict[str, bytes]) -> str:
    return environment().get_template("report.html.j2").render(title=title, sections=sections, images=images)
