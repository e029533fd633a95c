"""The first screen's figure where the paper's golf story does not apply: the compared data with their
top-ranked candidates, and the sentences beside it, every number read from the data and the ranking.

The golf story (``first_screen.SeriesFinding``: the paper's truncated series has its slip cross zero, so its
spin falls) is told only where the data's own spin falls; elsewhere this view says what the data do.
"""
from __future__ import annotations

import attrs
import numpy as np

from ..core.display import NAMES, fmt_time, unit
from .text import sig

#: candidates shown per dataset, best first
TOP = 3
#: datasets shown side by side
SHOWN = 2


@attrs.frozen
class DataView:
    """One dataset with the fits of its top-ranked candidates (best first) and, where the paper's series
    was fitted, its SeriesFinding."""

    dataset: object
    fits: tuple  # FitResult per candidate
    labels: tuple  # legend entry per candidate
    rows: tuple  # RankRow per candidate
    series: object = None  # first_screen.SeriesFinding or None


def spin_falls(d) -> bool:
    """Whether the dataset's spin column falls after its peak by more than twice its noise (False without one)."""
    w = d.columns.get("omega")
    if w is None or w.size < 3:
        return False
    return float(np.max(w) - w[-1]) > 2.0 * float(d.noise.get("omega", 0.0))


def data_views(c, findings) -> list[DataView]:
    """Up to SHOWN fitted datasets (measured first, time series before rows of impacts) with their top
    candidates; ``findings`` (SeriesFinding per dataset) fill the series-versus-exact part where fitted."""
    from .figures.fits import angle_column

    by_ds = {f.dataset.name: f for f in findings}
    drawable = [d for d in c.fitted_datasets if "t" in d.columns or angle_column(d) is not None]
    order = sorted(drawable, key=lambda d: (d.provenance.kind != "measured", "t" not in d.columns))
    out = []
    for d in order:
        rows = sorted((r for r in c.ranking if r.dataset == d.name and r.rank is not None),
                      key=lambda r: r.rank)[:TOP]
        picked = [(r, _fit_of(c, d.name, r)) for r in rows]
        picked = [(r, f) for r, f in picked if f is not None]
        if not picked:
            continue
        out.append(DataView(d, *_visible(picked), tuple(r for r, _ in picked), by_ds.get(d.name)))
        if len(out) == SHOWN:
            break
    return out


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
    return f"#{r.rank} {r.candidate}" + ("" if r.rank == 1 else f", ΔAIC {r.delta_aic:.1f}")


def title(views) -> str:
    """The figure's title, from what is shown."""
    names = " and ".join(v.dataset.name for v in views)
    return f"{names}: the data and the top-ranked laws" + (
        "; below, slip of the paper's series and of the exact solution" if any(v.series for v in views) else "")


def describe(v: DataView) -> str:
    """What the data do and how the top candidates rank, in sentences whose numbers come from the data."""
    return " ".join(s for s in (_shape(v), _ranked(v), _series(v)) if s)


def _shape(v: DataView) -> str:
    target = v.fits[0].per_dataset[0].target
    obs, y = target.observable, np.asarray(target.y, float)
    name = NAMES.get(obs, obs.replace("_", " "))
    if target.t is None:
        from .figures import column_unit

        cu, cf = column_unit(v.dataset, obs)
        return (f"{v.dataset.name}: {y.size} impacts; the observed {name} spans {sig(float(np.min(y)) * cf)} to "
                f"{sig(float(np.max(y)) * cf)}{' ' + cu if cu else ''}.")
    un, uf = unit(obs)
    t = np.asarray(target.t, float)
    q = lambda x: f"{sig(float(x) * uf)}" + (f" {un}" if un not in ("-", "", "1") else "")  # noqa: E731  no unit: no '-'
    i = int(np.argmax(y))
    noise = 2.0 * float(np.median(target.sigma))
    text = f"On {v.dataset.name} the observed {name} goes from {q(y[0])} to {q(y[-1])} over {fmt_time(t[-1])}"
    if 0 < i < y.size - 1 and y[i] - y[-1] > noise:
        return text + f", peaking at {q(y[i])} at {fmt_time(t[i], t[-1])} and then falling."
    if np.all(np.diff(y) >= -noise):
        return text + (" and never falls by more than twice its noise." if y[-1] > y[0] else ".")
    return text + "."


def _ranked(v: DataView) -> str:
    best = v.rows[0]
    verdict = {True: "it passes the goodness-of-fit test", False: "it fails the goodness-of-fit test",
               None: "no goodness-of-fit test"}[best.fits]
    text = f"Ranked first: {best.candidate} (reduced χ² {sig(best.redchi)}; {verdict})."
    rest = [f"{r.candidate} (ΔAIC {r.delta_aic:.1f})" for r in v.rows[1:]]
    return text + (" Then " + ", ".join(rest) + "." if rest else "")


def _series(v: DataView) -> str:
    s = v.series
    if s is None:
        return ""
    if s.t_cross is None:
        return (f"The paper's truncated series of {s.series.law} keeps its slip positive up to t_c = "
                f"{fmt_time(s.contact_time)}, as the {s.full.solver} solution does: neither reverses its friction.")
    return (f"The paper's truncated series of {s.series.law} has its slip cross zero at "
            f"{fmt_time(s.t_cross, s.contact_time)}, but these data's spin does not fall after its peak, so the "
            "paper's explanation of a falling spin has nothing to explain here.")
