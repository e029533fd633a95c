"""A comparison of many dataset groups as pages: an index (the verdict table of every group, the summary
and a link per group) and one page per group with every section restricted to that group's datasets, so
each page grows with its group, not with the whole comparison. ``write_report`` pages a comparison of
more than ``GROUP_PAGES_AT`` groups; results.json and ranking.csv stay whole.
"""
from __future__ import annotations

import re

import attrs

from .doc import Section

#: Dataset groups beyond which the report is an index page plus one page per group.
GROUP_PAGES_AT = 12
TITLE = "Dataset groups"


def groups_of(c) -> dict[str, list[str]]:
    """Group label -> its datasets' names, in the comparison's dataset order (``answers.group_of``)."""
    from ..inference.verdicts.answers import group_of

    out: dict[str, list[str]] = {}
    for d in c.datasets:
        out.setdefault(group_of(d), []).append(d.name)
    return out


def slug(group: str) -> str:
    """A file name for a group's page (letters, digits, '.', '-' and '_')."""
    return re.sub(r"[^A-Za-z0-9._-]", "_", group) or "_"


def restrict(c, names, group: str):
    """The comparison of the datasets ``names`` (one group) alone: every result about other datasets left out."""
    keep = set(names)

    def within(ds) -> bool:
        return set(ds) <= keep

    return attrs.evolve(
        c, datasets=tuple(d for d in c.datasets if d.name in keep),
        fits=tuple(f for f in c.fits if within(f.datasets)),
        ranking=tuple(r for r in c.ranking if r.dataset in keep),
        groups=tuple(r for r in c.groups if r.dataset == group),
        equivalence=tuple(e for e in c.equivalence if e.dataset in keep),
        skipped_datasets={k: v for k, v in c.skipped_datasets.items() if k in keep},
        bootstrap=tuple(b for b in c.bootstrap if within(b.datasets)),
        bootstrap_skipped={k: v for k, v in c.bootstrap_skipped.items() if k in keep},
        tolerance=tuple(r for r in c.tolerance if r.get("dataset") in keep),
        accuracy=tuple(r for r in c.accuracy if r.dataset in keep),
        transfer=tuple(t for t in c.transfer if within(t.datasets)),
        answers=tuple(a for a in c.answers if a.group == group))


def index_section(groups: dict[str, list[str]]) -> Section:
    """The list of group pages, one link each, with the group's datasets."""
    sec = Section(TITLE, open=True)
    sec.p(f"{len(groups)} dataset groups: each has its own page with its fits, rankings, tests and figures.")
    sec.links([(f"{g} ({len(names)} dataset{'s' * (len(names) != 1)})", f"groups/{slug(g)}.html")
               for g, names in groups.items()])
    return sec


def pages(c, sections_all, index_modules):
    """(relative path without suffix, comparison, section modules, figure folder) of every page: the index
    ``report`` and, per group, ``groups/<group>``."""
    groups = groups_of(c)
    out = [("report", c, index_modules, "figures", groups)]
    for g, names in groups.items():
        out.append((f"groups/{slug(g)}", restrict(c, names, g), sections_all, f"figures/{slug(g)}", None))
    return out
