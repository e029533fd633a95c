"""A long record is drawn from the points its pixels show (``report.figures.base.thinned``)."""
import numpy as np

from frictionlab.report.figures.base import THIN_AT, THIN_BINS, thinned


def test_a_short_series_keeps_every_point():
    t = np.linspace(0.0, 1.0, THIN_AT)
    assert np.array_equal(thinned(t, np.sin(t)), np.arange(THIN_AT))


def test_a_long_series_keeps_the_ends_and_each_columns_extremes():
    rng = np.random.default_rng(3)
    t = np.sort(rng.uniform(0.0, 7.0, 60_000))
    y, z = np.sin(t) + rng.normal(0.0, 0.2, t.size), rng.normal(0.0, 1.0, t.size)
    k = thinned(t, y, z)
    assert k.size < 6 * THIN_BINS and k[0] == 0 and k[-1] == t.size - 1 and np.all(np.diff(k) > 0)
    edges = np.linspace(t[0], t[-1], THIN_BINS + 1)
    col = np.clip(np.searchsorted(edges, t, side="right") - 1, 0, THIN_BINS - 1)
    for j in range(THIN_BINS):
        whole, kept = col == j, col[k] == j
        if whole.any():
            for s in (y, z):
                assert s[whole].max() == s[k][kept].max() and s[whole].min() == s[k][kept].min()
