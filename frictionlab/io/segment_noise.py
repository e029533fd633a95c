"""The noise of a load-point displacement record x(t), from the data (move 1 of ``io.segment``).

Difference-based pseudo-residuals (Gasser, Sroka and Jennen-Steinmetz 1986, Biometrika 73) x_i -
chord(x_{i-L}, x_{i+L}) vanish on any straight line. Over blocks of the record their robust scale (1.4826
times the median absolute value) at lag L = 1 is the white noise, and the largest over lags L = 1, 2, 4, ...
(chords that cross no breakpoint given) the total noise with the servo's slower wander; read as AR(1) noise,
the two give the long-run variance that weighs each sample. No record shows less noise than its digits
resolve: the least count of its displacement (an LVDT's count, or the last digit written) over sqrt(12), the
standard deviation of rounding to it.
"""
from __future__ import annotations

import math

import numpy as np

#: Samples per block of the noise by sample; largest lag there, and over a stretch.
BLOCK, MAX_LAG, MAX_STRETCH_LAG = 4096, 512, 4096
LD = np.longdouble  # extended precision where available: sums over long records keep their digits


def pseudo_residuals(t: np.ndarray, x: np.ndarray, lag: int) -> np.ndarray:
    """x_i minus the chord through x_{i-lag} and x_{i+lag}, scaled to the noise's standard deviation
    (for i = lag .. n - lag - 1)."""
    a, b, c = t[:-2 * lag], t[lag:-lag], t[2 * lag:]
    w = (b - a) / (c - a)
    return (x[lag:-lag] - ((1 - w) * x[:-2 * lag] + w * x[2 * lag:])) / np.sqrt(1 + w * w + (1 - w) ** 2)


def _lags(n: int, largest: int) -> list[int]:
    out = [1]
    while out[-1] * 2 <= min(largest, n // 16):
        out.append(out[-1] * 2)
    return out


def noise_by_sample(t: np.ndarray, x: np.ndarray, cuts=()) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(white, total, long-run variance) of the displacement noise by sample (move 1), from the
    pseudo-residuals whose samples lie between two of ``cuts`` (breakpoints already known)."""
    n = len(t)
    piece = np.searchsorted(np.asarray(cuts, dtype=int), np.arange(n), side="right")
    nb = max(1, round(n / BLOCK))
    edges = np.linspace(0, n, nb + 1).astype(int)
    lags = _lags(n, MAX_LAG)
    scale = np.full((len(lags), nb), np.nan)
    for k, lag in enumerate(lags):
        r = np.abs(pseudo_residuals(t, x, lag))
        if len(cuts):
            r[piece[:-2 * lag] != piece[2 * lag:]] = np.nan
        lo, hi = np.clip(edges[:-1] - lag, 0, r.size), np.clip(edges[1:] - lag, 0, r.size)
        for j in range(nb):
            rr = r[lo[j]:hi[j]]
            rr = rr[~np.isnan(rr)] if len(cuts) else rr
            if rr.size >= 8:
                scale[k, j] = 1.4826 * float(np.median(rr))
    floor = resolution(t, x)
    s1 = np.fmax(np.nan_to_num(scale[0], nan=floor), floor)
    total = np.fmax(np.nan_to_num(np.nanmax(scale, axis=0), nan=floor), s1)
    phi = ar1_coefficient(s1, total)
    per = np.repeat(np.arange(nb), np.diff(edges))
    return s1[per], total[per], (total ** 2 * (1 + phi) / (1 - phi))[per]


def ar1_coefficient(s1, total):
    """The coefficient phi of AR(1) noise of standard deviation ``total`` whose lag-1 pseudo-residuals have the
    scale ``s1``: sigma1^2 / sigma^2 = (1 - phi)(3 - phi) / 3 (0 for white noise, at most 0.99)."""
    q = np.clip((np.asarray(s1) / np.asarray(total)) ** 2, 1e-4, 1.0)
    return np.clip(2.0 - np.sqrt(1.0 + 3.0 * q), 0.0, 0.99)


def shift_noise(total: float, phi: float, k: int = 3) -> float:
    """The standard deviation of the mean of k samples less the mean of the k before them, for AR(1) noise of
    standard deviation ``total`` and coefficient ``phi``: total sqrt(2 / k) for white noise, and more for
    correlated noise, whose wander moves neighbouring samples together."""
    w = np.repeat([-1.0, 1.0], k) / k
    lag = np.abs(np.subtract.outer(np.arange(2 * k), np.arange(2 * k)))
    return float(total) * math.sqrt(max(float(w @ (float(phi) ** lag) @ w), 0.0))


def resolution(t: np.ndarray, x: np.ndarray) -> float:
    """The smallest noise a record can show: the rounding of its displacement to its least count (``least_count``
    over sqrt(12)), and at least what double precision resolves of it about the chord through its ends (a record
    without noise, exact to its last digit, still has pieces of finite cost)."""
    chord = x[0] + (x[-1] - x[0]) * (t - t[0]) / (t[-1] - t[0])
    return max(1e-8 * float(np.max(np.abs(x - chord))), least_count(x) / math.sqrt(12.0), 1e-150)


def least_count(x: np.ndarray) -> float:
    """The step of the grid the displacement's values lie on [x unit]: an LVDT's count, or the last digit written
    (``last_digit``): the typical smallest difference between successive samples when nearly every difference of
    up to ten of it is a whole multiple of it (within the last digit) and the differences vary (a line sampled
    exactly, its every difference the same, is no sign of a count); 0 when the values lie on no grid coarser
    than double precision."""
    digit = last_digit(x)
    d = np.abs(np.diff(x))
    nz = d[d > 0]
    if nz.size < 16 or sampled_exactly(x, digit):
        return digit
    q = float(np.median(nz[nz <= 1.5 * float(nz.min())]))
    small = nz[nz <= 10.5 * q]
    if small.size >= nz.size / 2:
        tol = 2 * digit + 1e-3 * q + 1e-13 * float(np.max(np.abs(x)))
        if np.mean(np.abs(small - np.round(small / q) * q) <= tol) >= 0.99:
            return max(q, digit)
    return digit


def sampled_exactly(x: np.ndarray, digit: float) -> bool:
    """True when the differences between successive samples stay the same (within half the last digit and
    double precision) at 99 % of the samples: straight lines sampled without noise, not a count's staircase."""
    d = np.diff(x)
    tol = 0.5 * digit + 1e-12 * float(np.max(np.abs(x)))
    return d.size > 2 and float(np.mean(np.abs(np.diff(d)) <= tol)) >= 0.99


def last_digit(x: np.ndarray) -> float:
    """The place of the last digit the values were written to: the largest 10^-k (k = 0 ... 15) that every value
    (of up to 100 000 spread over the record) is a whole multiple of; 0 when none is (full double precision)."""
    v = np.asarray(x[::max(1, len(x) // 100_000)], dtype=float)
    for k in range(16):
        y = v * 10.0 ** k
        if float(np.max(np.abs(y))) > 1e13:
            break
        if np.all(np.abs(y - np.round(y)) <= 1e-2):
            return 10.0 ** -k
    return 0.0


class StretchNoise:
    """The noise of any stretch [a, b) of a record: the root mean square of the pseudo-residuals inside it,
    the largest over lags 1, 2, 4, ... up to (b - a) / parts (prefix sums on a grid, so O(1) a query); for a
    stretch too short for that, the root mean square of ``floor``, the noise by sample, over it."""

    def __init__(self, t, x, grid, floor: np.ndarray):
        self.grid, self.floor = np.asarray(grid), np.concatenate([[0.0], np.cumsum(floor ** 2)])
        self.least = resolution(t, x)
        self.lags = _lags(len(t), MAX_STRETCH_LAG)
        self.S = []
        for lag in self.lags:  # sums of r^2 by centre index, at the grid positions
            r2 = np.zeros(len(t))
            r2[lag:-lag] = pseudo_residuals(t, x, lag) ** 2
            self.S.append(np.concatenate([[0.0], np.cumsum(np.add.reduceat(r2, self.grid[:-1]), dtype=LD)]))

    def __call__(self, a: int, b: int, parts: int = 16) -> float:
        best = 0.0
        for lag, S in zip(self.lags, self.S):
            if parts * lag > b - a and lag > 1:
                break
            i, j = np.searchsorted(self.grid, a + lag), np.searchsorted(self.grid, b - lag, side="right") - 1
            if self.grid[j] - self.grid[i] >= 8:
                best = max(best, float((S[j] - S[i]) / (self.grid[j] - self.grid[i])))
            elif lag == 1:  # too short a stretch: the noise by sample there
                return math.sqrt((self.floor[b] - self.floor[a]) / (b - a))
        return max(math.sqrt(best), self.least)


