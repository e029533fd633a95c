"""The healing table of a slide-hold-slide record, as a laboratory reports it, beside each state law's prediction.

For every hold of the load-point history (a piece at V = 0 between two sliding pieces):

* hold time t_h [s]: the hold's length in the schedule;
* steady friction mu_ss before the hold: the line fitted to friction over the second half of the sliding piece
  before it, at the hold's start (a trend, if any, is not mistaken for healing);
* peak friction on re-sliding: the largest running mean of friction over ``smooth`` samples in the sliding piece
  after the hold (a single noisy sample would bias the peak by about two noise sigma);
* healing dmu = peak - mu_ss.

The healing rate is the slope beta = d(dmu) / d(log10 t_h) per decade of hold time, fitted by least squares,
with its 95 % interval from Student's t on n - 2 degrees of freedom (n >= 3 holds). A law's prediction is the
same table read off the law's friction at its fitted (or given) parameters, without noise, on the same
history: the aging law heals with log hold time (Dieterich 1972; Beeler et al. 1994), the slip law, which lets
state evolve only with slip, heals far less on a stiff machine (Ruina 1983; Bhattacharya et al. 2017).
"""
from __future__ import annotations

import math

import attrs
import numpy as np

from ...core.errors import DatasetError

#: Samples of the running mean the peak is read from.
SMOOTH = 5


@attrs.frozen
class Hold:
    """One hold: its length [s], the friction before it and at the peak after it, and the healing."""

    start: float  # s, on the dataset's clock
    hold: float  # s
    mu_ss: float
    peak: float

    @property
    def healing(self) -> float:
        return self.peak - self.mu_ss


@attrs.frozen
class HealingTable:
    """The holds of one record and the healing rate per decade of hold time with its 95 % interval."""

    source: str  # 'data' or the law the friction comes from
    holds: tuple
    beta: float = math.nan  # d(dmu) / d(log10 t_h)
    beta_se: float = math.nan
    beta_lo: float = math.nan
    beta_hi: float = math.nan

    def as_rows(self) -> list[dict]:
        return [{"hold [s]": h.hold, "mu_ss": h.mu_ss, "peak": h.peak, "healing": h.healing} for h in self.holds]


def holds_of(times, velocities, t_end: float) -> list[tuple[int, float, float]]:
    """(piece, start [s], length [s]) of every hold of a schedule (segment start times, velocities) between
    two sliding pieces (a record that starts or ends in a hold has no re-slide to read)."""
    times, v = list(times) + [t_end], list(velocities)
    return [(k, float(times[k]), float(times[k + 1] - times[k])) for k in range(1, len(v) - 1)
            if v[k] == 0 and v[k - 1] > 0 and v[k + 1] > 0]


def healing_table(t, mu, times, velocities, source: str = "data", smooth: int = SMOOTH) -> HealingTable:
    """The healing table of friction ``mu`` at times ``t`` [s] under the schedule ``times`` [s, from t = 0] and
    ``velocities`` [m/s] (module docstring); a DatasetError when the schedule holds no hold or a piece around
    one has too few samples."""
    t, mu = np.asarray(t, dtype=float), np.asarray(mu, dtype=float)
    edges = list(times) + [math.inf]
    out = []
    for k, start, length in holds_of(times, velocities, float(t[-1])):
        before = (t >= edges[k - 1]) & (t < edges[k])
        after = (t >= edges[k + 1]) & (t < edges[k + 2])
        if before.sum() < 6 or after.sum() < smooth:
            raise DatasetError(f"the hold at t = {start:g} s: {int(before.sum())} samples of sliding before it and "
                               f"{int(after.sum())} after it; the healing table needs at least 6 and {smooth}")
        tb, yb = t[before], mu[before]
        half = tb.size // 2
        _, icpt = np.polyfit(tb[half:] - start, yb[half:], 1)
        ya = mu[after]
        peak = float(np.max(np.convolve(ya, np.ones(smooth) / smooth, mode="valid")))
        out.append(Hold(start, length, float(icpt), peak))
    if not out:
        raise DatasetError("the load-point schedule holds no hold between two sliding pieces: no healing to report")
    return _with_rate(HealingTable(source, tuple(out)))


def _with_rate(table: HealingTable) -> HealingTable:
    """The table with beta, its standard error and 95 % interval (n >= 3 holds of at least two lengths)."""
    from scipy.stats import t as student

    x = np.log10([h.hold for h in table.holds])
    y = np.array([h.healing for h in table.holds])
    n = x.size
    if n < 3 or np.ptp(x) == 0:
        return table
    sxx = float(np.sum((x - x.mean()) ** 2))
    beta = float(np.sum((x - x.mean()) * (y - y.mean())) / sxx)
    resid = y - (y.mean() + beta * (x - x.mean()))
    se = math.sqrt(float(resid @ resid) / (n - 2) / sxx)
    q = float(student.ppf(0.975, n - 2))
    return attrs.evolve(table, beta=beta, beta_se=se, beta_lo=beta - q * se, beta_hi=beta + q * se)


def of_dataset(dataset, mu=None, source: str = "data") -> HealingTable:
    """The healing table of a spring-slider Dataset (``mu``: another friction series at its times, e.g. a law's
    prediction)."""
    spring = dataset.scene.spring
    return healing_table(dataset.t, dataset.y if mu is None else mu, spring.times, spring.velocities, source)


def lines(tables: list[HealingTable]) -> list[str]:
    """The tables side by side as text: one row per hold, one healing column per source, then the rates."""
    head = ["hold [s]", "mu_ss (data)"] + [f"healing ({t.source})" for t in tables]
    rows = [head]
    for i, h in enumerate(tables[0].holds):
        rows.append([f"{h.hold:.4g}", f"{h.mu_ss:.5f}"] + [f"{t.holds[i].healing:.5f}" for t in tables])
    rate = ["per decade", ""] + [f"{t.beta:.5f} [{t.beta_lo:.5f}, {t.beta_hi:.5f}]" if math.isfinite(t.beta) else "—"
                                 for t in tables]
    rows.append(rate)
    widths = [max(len(r[j]) for r in rows) for j in range(len(head))]
    return ["  " + "  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]
