"""Start points of a fit: a grid over each free parameter's span (linear, logarithmic about the start, or dense near
it), a Latin hypercube between the grid's levels, and the best distinct points of a scored grid. Values are SI."""
from __future__ import annotations

import math

import numpy as np


def start_grid(slots, rng, limit: int, decades: float = 1.5) -> list[dict[str, float]]:
    """Candidate starts in scaled units, the given start first: log-spaced multiples of the start
    for positive quantities (10^-decades to 10^decades), steps of the scale around it for signed ones, the
    bounds' span for scene quantities; clipped into the bounds. A full grid if it has at most ``limit`` points,
    else ``limit`` points of it drawn at random."""
    levels = max(3, min(15, int(round(limit ** (1.0 / len(slots))))))
    axes = []
    for s in slots:
        x0 = s.value / s.scale
        lo, hi = s.lower / s.scale, s.upper / s.scale
        if s.kind == "scene":
            c = np.linspace(lo, hi, levels)
        elif lo >= 0 and x0 > 0:
            c = x0 * np.logspace(-decades, decades, levels)
        else:
            c = x0 + np.sinh(np.linspace(-4.0, 4.0, levels))  # dense near the start, out to +/- 27 scales
        axes.append(np.unique(np.clip(c, lo, hi)))
    total = math.prod(len(a) for a in axes)
    if total <= limit:
        grid = np.array(np.meshgrid(*axes, indexing="ij")).reshape(len(axes), -1).T
    else:
        grid = np.array([[rng.choice(a) for a in axes] for _ in range(limit)])
    return as_starts(slots, grid)


def sampled_starts(slots, rng, limit: int, decades: float = 1.5) -> list[dict[str, float]]:
    """As ``start_grid``, ``limit`` points of a Latin hypercube over the same spans instead of a grid's levels,
    every axis continuous (rate-and-state's a and b trade off: where the data want b near 0, the levels hold no a
    that matches them, and the grid's best starts all have b large)."""
    from scipy.stats import qmc

    u = qmc.LatinHypercube(d=len(slots), seed=rng).random(limit)
    axes = []
    for s, w in zip(slots, u.T):
        x0, lo, hi = s.value / s.scale, s.lower / s.scale, s.upper / s.scale
        if s.kind == "scene":
            c = lo + (hi - lo) * w
        elif lo >= 0 and x0 > 0:
            c = x0 * 10.0 ** (decades * (2.0 * w - 1.0))
        else:
            c = x0 + np.sinh(8.0 * w - 4.0)
        axes.append(np.clip(c, lo, hi))
    return as_starts(slots, np.array(axes).T)


def as_starts(slots, grid) -> list[dict[str, float]]:
    """The given start (scaled), then each row of ``grid``, as {parameter name: scaled value}."""
    grid = np.vstack([[s.value / s.scale for s in slots], grid])
    return [dict(zip((s.pname for s in slots), row)) for row in grid]


def distinct(scored: list[tuple], n: int) -> list[dict]:
    """Up to n starts from (cost, order, candidate) sorted by cost: each differs from those taken by
    more than 10% in some coordinate and has a different cost (equal costs mean a plateau, such as
    a body stuck throughout, where a second start teaches nothing)."""
    out, costs = [], []
    for cost, _, c in scored:
        if any(abs(cost - k) <= 1e-9 * max(abs(cost), 1e-300) for k in costs):
            continue
        if all(any(abs(c[k] - o[k]) > 0.1 * max(abs(c[k]), abs(o[k]), 1e-3) for k in c) for o in out):
            out.append(c)
            costs.append(cost)
        if len(out) == n:
            break
    return out
