"""The first screen's figure and the sentences beside it: per dataset group, one of its datasets with the group's
top-ranked candidates, every number read from the data and the ranking.

A group's top-ranked candidates are its rank-1 rows (the group's own ranking where it has two or more members,
else its dataset's). The slip of the truncated series and of the exact solution of the same law is drawn only
where such a series is among them. The paper's own story (its truncated series' slip crosses zero, so its spin
falls) is told only for data whose provenance is the paper's (``Provenance.seed_paper``) and whose spin falls.
"""
from __future__ import annotations

import attrs
import numpy as np

from ..core.display import NAMES, fmt_time, unit
from ..inference.verdicts.answers import group_of
from ..inference.verdicts.ranking import family
from .text import sig

@attrs.frozen
class DataView:
    """One dataset of a group with the fits of the group's top-ranked candidates and, where one of them is the
    truncated series, its SeriesFinding (the series against the exact solution of the same law)."""

    dataset: object
    fits: tuple  # FitResult per candidate
    labels: tuple  # legend entry per candidate
    rows: tuple  # the dataset's RankRow per candidate
    series: object = None  # first_screen.SeriesFinding or None
    group: str = ""
    group_rows: tuple = ()  # the group's rank-1 rows (the dataset's own for a group of one)


def spin_falls(d) -> bool:
    """Whether the dataset's spin column falls after its peak by more than twice its noise (False without one)."""
    w = d.columns.get("omega")
    if w is None or w.size < 3:
        return False
    return float(np.max(w) - w[-1]) > 2.0 * float(d.noise.get("omega", 0.0))


def group_views(c, findings, skip=frozenset()) -> list[DataView]:
    """One view per dataset group with a fitted law (in order of first appearance; groups whose datasets all have
    a first-screen block of their own drew, ``skip`` (names), are left to it): the group's first drawable dataset
    (measured first, time series first) with the group's top-ranked candidates fitted to it."""
    from .figures.fits import angle_column

    by_ds = {f.dataset.name: f for f in findings}
    members: dict[str, list] = {}
    for d in c.fitted_datasets:
        if d.name not in skip and ("t" in d.columns or angle_column(d) is not None):
            members.setdefault(group_of(d), []).append(d)
    out = []
    for label, dss in members.items():
        top = _group_top(c, label, dss)
        for d in sorted(dss, key=lambda d: (d.provenance.kind != "measured", "t" not in d.columns)):
            picked = [(r, f) for r, f in ((r, _fit_of(c, d.name, r)) for r in _rows_on(c, d.name, top))
                      if f is not None]
            if not picked:
                continue
            series = by_ds.get(d.name)
            if series is not None and not any(f.solver == "series" and f.law == series.series.law for _, f in picked):
                series = None  # the series is not among the top-ranked: no slip panel
            out.append(DataView(d, *_visible(picked), tuple(r for r, _ in picked), series, label, tuple(top)))
            break
    return out


def _group_top(c, label: str, dss) -> list:
    """The group's rank-1 rows: its own ranking for two or more members, else its dataset's."""
    pool = [r for r in c.groups if r.dataset == label] if len(dss) > 1 else []
    if not pool:
        pool = [r for r in c.ranking if r.dataset == dss[0].name]
    return [r for r in pool if r.rank == 1]


def _rows_on(c, dataset: str, top) -> list:
    """The dataset's ranking rows of the group's top candidates (same law label, same solver family)."""
    want = {(r.law, family(r.solver)) for r in top}
    rows = [r for r in c.ranking if r.dataset == dataset and r.rank is not None and (r.law, family(r.solver)) in want]
    return sorted(rows, key=lambda r: r.rank)


def _visible(picked) -> tuple[tuple, tuple]:
    """(fits, legend labels) with a candidate whose curve lies under a better one's (figures.base.HIDDEN)
    named in that one's entry and not drawn."""
    from .figures.base import HIDDEN

    span = float(np.ptp(picked[0][1].per_dataset[0].target.y)) or 1.0
    fits, labels = [], []
    for r, f in picked:
        m = f.per_dataset[0].model
        under = next((i for i, g in enumerate(fits) if g.per_dataset[0].model.shape == m.shape
                      and np.all(np.abs(g.per_dataset[0].model - m) <= HIDDEN * span)), None)
        if under is None:
            fits.append(f)
            labels.append(_legend(r))
        else:
            labels[under] += f" (hides {_legend(r)})"
    return tuple(fits), tuple(labels)


def _fit_of(c, dataset: str, row):
    return next((f for f in c.fits_on(dataset) if f.ok and f.solver == row.solver
                 and f.law in (row.members or (row.law,))), None)


def _legend(r) -> str:
    return f"#{r.rank} {r.candidate}"


def title(views) -> str:
    """The figure's title, from what is shown."""
    text = "Each dataset group: the data and its top-ranked candidates"
    if any(v.series for v in views):
        text += "; below, the slip u(t) of the truncated series and of the exact solution of the same law"
    return text


def describe(v: DataView) -> str:
    """What the data do and what ranks first, in sentences whose numbers come from the data; the paper's story
    only for the paper's data."""
    return " ".join(s for s in (_shape(v), _ranked(v), _series(v)) if s)


def _shape(v: DataView) -> str:
    target = v.fits[0].per_dataset[0].target
    group = getattr(v, "group", "") or v.dataset.name
    head = f"**{group}**" + ("" if group == v.dataset.name else f" ({v.dataset.name})")
    if target.observable == "stated":
        st = v.dataset.stated
        if {"omega_peak", "t_peak", "omega_end"} <= set(st):
            un, uf = unit("omega")
            return (f"{head}: the stated spin peaks at {sig(st['omega_peak'][0] * uf)} {un} at "
                    f"{fmt_time(st['t_peak'][0])} and falls to {sig(st['omega_end'][0] * uf)} {un} at the end of "
                    "contact.")
        return f"{head}: {len(target.y)} stated numbers."
    obs, y = target.observable, np.asarray(target.y, float)
    name = NAMES.get(obs, obs.replace("_", " "))
    if target.t is None:
        from .figures import column_unit

        cu, cf = column_unit(v.dataset, obs)
        return (f"{head}: {y.size} impacts; the observed {name} spans {sig(float(np.min(y)) * cf)} to "
                f"{sig(float(np.max(y)) * cf)}{' ' + cu if cu else ''}.")
    un, uf = unit(obs)
    t = np.asarray(target.t, float)
    q = lambda x: f"{sig(float(x) * uf)}" + (f" {un}" if un not in ("-", "", "1") else "")  # noqa: E731  no unit: no '-'
    i = int(np.argmax(y))
    noise = 2.0 * float(np.median(target.sigma))
    text = f"{head}: the observed {name} goes from {q(y[0])} to {q(y[-1])} over {fmt_time(t[-1])}"
    if 0 < i < y.size - 1 and y[i] - y[-1] > noise:
        return text + f", peaking at {q(y[i])} at {fmt_time(t[i], t[-1])} and then falling."
    if np.all(np.diff(y) >= -noise):
        return text + (" and never falls by more than twice its noise." if y[-1] > y[0] else ".")
    return text + "."


def _ranked(v: DataView) -> str:
    best = v.group_rows[0] if v.group_rows else v.rows[0]
    names = " = ".join(dict.fromkeys(r.candidate for r in (v.group_rows or v.rows[:1])))
    verdict = {True: "it passes its fit tests", False: "it fails its fit tests", None: "no fit test"}[best.fits]
    if best.flags:
        verdict += ", flagged as implausible"
    return f"Ranked first: {names} ({verdict})."


def _series(v: DataView) -> str:
    s = v.series
    if s is None:
        return ""
    paper = v.dataset.provenance.seed_paper
    which = "The paper's truncated series" if paper else "The truncated series"
    if s.t_cross is None:
        return (f"{which} keeps its slip positive up to t_c = {fmt_time(s.contact_time)}, as the {s.full.solver} "
                "solution does: neither reverses its friction.")
    text = (f"{which} has its slip u(t) cross zero at {fmt_time(s.t_cross, s.contact_time)} "
            f"(t_c = {fmt_time(s.contact_time)}): from there its friction pushes the other way")
    if spin_falls(v.dataset):
        text += " and its spin falls"
        if s.full_min_slip > 0:
            text += (f"; the {s.full.solver} solution of the same law keeps u > 0 (at least {s.full_min_slip:.3g} m/s), "
                     "so its spin never falls: the fall comes from the truncation, not from the law")
        return text + "."
    return text + ", but these data's spin does not fall after its peak."
