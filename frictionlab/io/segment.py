"""Where a load-point displacement record x(t) changes its velocity: an exact piecewise-linear segmentation.

The record is taken as straight pieces plus noise and segmented in five moves:

1. **Noise, from the data.** Difference-based pseudo-residuals (Gasser, Sroka and Jennen-Steinmetz 1986,
   Biometrika 73) x_i - chord(x_{i-L}, x_{i+L}) vanish on any straight line. Over blocks of the record
   their robust scale (1.4826 times the median absolute value) at lag L = 1 is the white noise, and the
   largest over lags L = 1, 2, 4, ... is the total noise with the servo's slower wander; read as AR(1)
   noise, the two give the long-run variance that weighs each sample in move 2. Over a stretch of the
   record, the root mean square of the pseudo-residuals inside it, largest over lags up to a quarter of its
   length (to merge, move 4) or a sixteenth (to check a piece is straight: a bend is not noise), is the
   stretch's noise.
2. **Optimal partitioning with pruning** (PELT: Killick, Fearnhead and Eckley 2012, JASA 107, 1590): the
   partition minimising the sum over pieces of the weighted squared residuals about each piece's own
   least-squares line, plus a penalty of 3 ln n per piece (BIC: a line and a breakpoint), with O(1) costs
   from prefix sums. A record of more than ``GRID`` samples is partitioned exactly over a grid of
   candidate breakpoints (every sample within ``DENSE`` samples of either end, so that a change near an
   end is seen), and each breakpoint then moves to the best sample between its grid neighbours.
3. **Jumps.** A breakpoint where the displacement jumps (sharply: three samples after it stand off the
   three before by more than ``SHARP`` times the noise of that difference, from the white and total noise
   read as AR(1) noise: a correlated wander moves neighbouring samples together and is no jump) with no
   change of slope (parallel lines cost less than the penalty more than free ones) is a transducer reset or
   a servo correction: it is stitched (the samples after it shifted back by the jump) and reported.
4. **Merges.** Neighbouring pieces are merged, the straightest union first, while each piece strays from
   the union's line by at most ``MERGE`` times the two pieces' pooled noise (root mean square): drift and wander of the servo are not velocity steps. What is left
   are the steps; each piece between them must be straight within ``STRAIGHT`` times its noise, else the
   record is refused by where it is not.
5. **Step times.** Each step's time is the kink of the continuous two-line fit x = x_s + V(t) (t - t_s)
   (V = V1 before t_s, V2 after) over the stitched samples from the step before to the step after, t_s
   found by least squares as a continuous variable (never moved to a sample). Velocities come from one
   continuous fit through every kink. Standard errors: the larger of the fit's Jacobian with the residual
   variance inflated by (1 + r) / (1 - r) (r: the residuals' lag-1 autocorrelation) and with the long-run
   variance of move 1.

Times in s, displacements in any unit (velocities in that unit per second). Errors are ``DatasetError``
messages that start with ``where`` and name a sample by ``line(i)``, its line in the record.
"""
from __future__ import annotations

import math
from collections.abc import Callable

import attrs
import numpy as np

from ..core.errors import DatasetError
from .segment_noise import (LD, StretchNoise, ar1_coefficient, last_digit, least_count, noise_by_sample,
                            resolution, sampled_exactly, shift_noise)

#: Fewest samples of each velocity a step needs on either side.
MIN_PIECE = 20
#: Above this many samples the partition runs over a grid of about GRID candidate breakpoints.
GRID = 1000
#: Samples at either end of the record that are always candidate breakpoints.
DENSE = 200
#: A union of two pieces is one line within MERGE times its noise; a piece between steps must be straight
#: within STRAIGHT times its noise; a jump stands off by SHARP times its white noise.
MERGE, STRAIGHT, SHARP = 3.0, 2.0, 5.0
CHUNK = 1 << 18  # samples handled at once where a long record would need large temporaries


@attrs.frozen
class Step:
    """A change of load-point velocity: time [s] and velocities [x unit/s] with standard errors."""

    index: int  # first sample after the step
    time: float
    time_se: float
    v1: float
    v1_se: float
    v2: float
    v2_se: float
    rms: float  # residual rms of the kink fit [x unit]


@attrs.frozen
class Jump:
    """A jump of displacement without a change of velocity, stitched: ``size`` [x unit] before sample ``index``."""

    index: int
    size: float
    size_se: float


@attrs.frozen
class Segmentation:
    """Steps, jumps, the pieces' velocities, the stitched displacement and the noise."""

    steps: tuple  # Step, in time order
    jumps: tuple  # Jump, in time order
    bounds: tuple  # sample indices of the pieces between steps: (0, steps[0].index, ..., n)
    velocities: tuple  # fitted velocity of each piece, one continuous fit through every kink [x unit/s]
    velocities_se: tuple
    x: np.ndarray = attrs.field(eq=False)  # the displacement, jumps stitched
    noise: float = 0.0  # the record's typical total displacement noise (median over samples)
    exact_to: float = 0.0  # the least count [x unit] when the record shows no noise beyond it, else 0
    breakpoints: tuple = ()  # every breakpoint of the optimal partition (move 2)
    penalty: float = 0.0


# --- sums and line costs -------------------------------------------------------------------------
class Moments:
    """Weighted moments (w, wt, wt^2, wx, wx^2, wtx) of any range of samples: prefix sums at grid positions
    in extended precision plus at most one grid interval summed directly, on times and displacements
    centred by a chord through the record so that short ranges keep their digits."""

    def __init__(self, t, x, w, grid):
        self.t0 = float(t[len(t) // 2])
        self.tt = t - self.t0
        slope = (x[-1] - x[0]) / (t[-1] - t[0])
        self.xx = x - (float(x[len(x) // 2]) + slope * self.tt)
        self.w = np.broadcast_to(np.asarray(w, dtype=float), self.tt.shape)
        self.grid = np.asarray(grid)
        self.S = np.zeros((6, len(self.grid)), dtype=LD)
        step = max(1, CHUNK * len(self.grid) // len(self.tt))
        for lo in range(0, len(self.grid) - 1, step):  # in chunks of about CHUNK samples: bounded memory
            g = self.grid[lo:lo + step + 1]
            blocks = np.add.reduceat(self._cols(g[0], g[-1]), g[:-1] - g[0], axis=1)
            self.S[:, lo + 1:lo + len(g)] = self.S[:, lo:lo + 1] + np.cumsum(blocks.astype(LD), axis=1)

    def _cols(self, a: int, b: int) -> np.ndarray:
        w, tt, xx = self.w[a:b], self.tt[a:b], self.xx[a:b]
        return np.stack([w, w * tt, w * tt * tt, w * xx, w * xx * xx, w * tt * xx])

    def upto(self, i: int) -> np.ndarray:
        """Sums over samples [0, i)."""
        g = int(np.searchsorted(self.grid, i, side="right")) - 1
        return self.S[:, g] + self._cols(int(self.grid[g]), i).sum(axis=1, dtype=LD)

    def between(self, a: int, b: int) -> np.ndarray:
        return self.upto(b) - self.upto(a)

    def prefix(self, lo: int, hi: int) -> np.ndarray:
        """Sums over [0, i) for every i in lo .. hi (6 x (hi - lo + 1))."""
        out = np.empty((6, hi - lo + 1), dtype=LD)
        out[:, 0] = self.upto(lo)
        np.cumsum(self._cols(lo, hi).astype(LD), axis=1, out=out[:, 1:])
        out[:, 1:] += out[:, :1]
        return out


def line_rss(D) -> np.ndarray:
    """Weighted residual sum of squares about the best line of ranges with moment sums D (6 x ...)."""
    W, St, Stt, Sx, Sxx, Stx = D  # in extended precision: a long piece's sums cancel to its small residual
    with np.errstate(invalid="ignore", divide="ignore"):
        Wp = np.where(W > 0, W, 1)
        vt, vx, c = Stt - St * St / Wp, Sxx - Sx * Sx / Wp, Stx - St * Sx / Wp
        r = vx - np.where(vt > 0, c * c / np.where(vt > 0, vt, 1), 0)
    return np.maximum(np.where(W > 0, r, 0), 0).astype(float)


def line_params(D) -> tuple:
    """(intercept, slope) of the weighted least-squares line of a range with moment sums D."""
    W, St, Stt, Sx, _, Stx = D
    vt = Stt - St * St / W
    slope = (Stx - St * Sx / W) / vt if vt > 0 else LD(0)
    return (Sx - slope * St) / W, slope


def rss_about(D, line) -> float:
    """Weighted squared residuals of a range with moment sums D about the line (intercept, slope)."""
    W, St, Stt, Sx, Sxx, Stx = D
    c, m = line
    return max(float(Sxx - 2 * c * Sx - 2 * m * Stx + c * c * W + 2 * c * m * St + m * m * Stt), 0.0)


def jump_rss(L, R) -> float:
    """Two parallel lines (one slope, an offset at the break) through ranges with sums L and R."""
    L, R = np.asarray(L, dtype=float), np.asarray(R, dtype=float)
    T = L + R
    A = np.array([[L[0], 0, L[1]], [0, R[0], R[1]], [L[1], R[1], T[2]]])
    b = np.array([L[3], R[3], T[5]])
    p = np.linalg.lstsq(A, b, rcond=None)[0]
    return max(T[4] - float(p @ b), 0.0)


# --- optimal partitioning ------------------------------------------------------------------------
def pelt(M: Moments, penalty: float, min_size: int = 3) -> list[int]:
    """Breakpoints (sample indices, grid positions of ``M``) of the partition minimising the pieces' line
    costs plus ``penalty`` per piece (PELT; a split never raises a line cost, so candidates are pruned
    when they cost more than the optimum without the penalty)."""
    P, S = M.grid, M.S
    K = len(P)
    F = np.full(K, np.inf)
    F[0] = -penalty
    last = np.zeros(K, dtype=int)
    cand = np.array([0])
    for k in range(1, K):
        cost = F[cand] + line_rss(S[:, k:k + 1] - S[:, cand])
        ok = P[k] - P[cand] >= min_size
        if ok.any():
            j = int(np.argmin(np.where(ok, cost, np.inf)))
            F[k], last[k] = cost[j] + penalty, cand[j]
            cand = cand[(cost <= F[k]) | ~ok]
        cand = np.append(cand, k)
    out, k = [], K - 1
    while (k := last[k]) > 0:
        out.append(int(P[k]))
    return out[::-1]


def grid(n: int) -> np.ndarray:
    """Candidate breakpoints: every sample up to GRID samples, else a grid of about GRID plus both ends."""
    if n <= GRID:
        return np.arange(n + 1)
    g = math.ceil(n / GRID)
    return np.unique(np.concatenate([np.arange(0, min(DENSE, n)), np.arange(0, n + 1, g),
                                     np.arange(max(n - DENSE, 0), n + 1)]))


def _refine(M: Moments, bps: list[int], n: int) -> list[int]:
    """Each breakpoint moved to the sample, between its grid neighbours, that minimises its pieces' costs;
    two breakpoints of the coarse grid's interior one grid interval apart (a change between grid positions
    approached from both sides) are first taken as one."""
    P = M.grid
    out = []
    for p in bps:
        k = int(np.searchsorted(P, p))
        if out and k > 0 and P[k - 1] == out[-1] and p - out[-1] > 1 and DENSE <= out[-1] and p <= n - DENSE:
            continue
        out.append(p)
    for i, p in enumerate(out):
        a, b = out[i - 1] if i else 0, out[i + 1] if i + 1 < len(out) else n
        k = int(np.searchsorted(P, p))
        lo, hi = max(int(P[max(k - 1, 0)]), a + 3), min(int(P[min(k + 1, len(P) - 1)]), b - 3)
        if hi > lo:
            pre = M.prefix(lo, hi)
            A, B = M.upto(a), M.upto(b)
            out[i] = lo + int(np.argmin(line_rss(pre - A[:, None]) + line_rss(B[:, None] - pre)))
    return out


# --- fits and their errors -------------------------------------------------------------------------
def errors(J: np.ndarray, res: np.ndarray, long_run: np.ndarray | None = None) -> np.ndarray:
    """Standard errors of a least-squares fit with Jacobian J and residuals res under correlated noise: the
    larger of (a) the residual variance inflated by (1 + r) / (1 - r), r the residuals' lag-1
    autocorrelation, and (b) the long-run variance by sample (``noise_by_sample``), which also sees wander
    slower than the fitted stretch."""
    n, p = J.shape
    rr = float(res @ res)
    r1 = min(max(float(res[1:] @ res[:-1]) / rr, 0.0), 0.99) if rr > 0 else 0.0
    with np.errstate(all="ignore"):
        try:
            var = np.diag(np.linalg.inv(J.T @ J)) * rr / max(n - p, 1) * (1 + r1) / (1 - r1)
            if long_run is not None:
                G = sum(J[i:i + CHUNK].T @ (J[i:i + CHUNK] / long_run[i:i + CHUNK, None]) for i in range(0, n, CHUNK))
                var = np.fmax(var, np.diag(np.linalg.inv(G)))
        except np.linalg.LinAlgError:
            return np.full(p, np.nan)
    return np.sqrt(np.clip(var, 0.0, None))


def kink_fit(t, x, a: int, b: int, j0: int, long_run: np.ndarray | None = None, reach: int = 500) -> Step:
    """The continuous two-line fit x = x_s + V(t)(t - t_s) over samples [a, b), its kink within ``reach``
    samples of j0: every sample scanned as the kink, then t_s by least squares between samples."""
    from scipy.optimize import minimize_scalar

    tc, xc = float(t[j0]), float(x[j0])
    tt, xx = t[a:b] - tc, x[a:b] - xc
    n, k0 = b - a, j0 - a
    lo, hi = max(k0 - reach, 1), min(k0 + reach + 2, n)  # prefix sums kept only where the kink may lie

    def prefix(v):  # sums of v over [0, j) for j = lo .. hi, and over everything
        out = np.empty(hi - lo + 1, dtype=LD)
        out[0] = np.sum(v[:lo], dtype=LD)
        np.cumsum(v[lo:hi], dtype=LD, out=out[1:])
        out[1:] += out[0]
        return out, out[0] + np.sum(v[lo:], dtype=LD)

    (c1, n1), (c2, n2), (cx, nx), (ctx, ntx) = prefix(tt), prefix(tt * tt), prefix(xx), prefix(tt * xx)
    sxx = np.sum(xx * xx, dtype=LD)

    def solve(j, tau):  # (rss, c, V1, V2) with samples [0, j) left of the kink at tau, by elimination
        tau, i = LD(tau), j - lo
        l1, l2 = c1[i] - tau * j, c2[i] - 2 * tau * c1[i] + tau * tau * j
        r1 = (n1 - c1[i]) - tau * (n - j)
        r2 = (n2 - c2[i]) - 2 * tau * (n1 - c1[i]) + tau * tau * (n - j)
        bl, br = ctx[i] - tau * cx[i], (ntx - ctx[i]) - tau * (nx - cx[i])
        c = (nx - l1 * bl / l2 - r1 * br / r2) / (n - l1 * l1 / l2 - r1 * r1 / r2)
        v1, v2 = (bl - l1 * c) / l2, (br - r1 * c) / r2
        return float(sxx - c * nx - v1 * bl - v2 * br), float(c), float(v1), float(v2)

    def rss(j, tau):
        return solve(j, tau)[0]

    js = range(max(lo, 2), min(hi, n - 1))
    k = min(js, key=lambda j: rss(j, tt[j]))
    best = (rss(k, tt[k]), float(tt[k]), k)
    for j in (k, k + 1):  # the kink in (t_{j-1}, t_j): samples [0, j) on the left
        if 2 <= j <= n - 2:
            r = minimize_scalar(lambda s, j=j: rss(j, s), bounds=(tt[j - 1], tt[j]), method="bounded",
                                options={"xatol": 1e-9 * (tt[j] - tt[j - 1])})
            if r.fun < best[0]:
                best = (float(r.fun), float(r.x), j)
    _, ts, j = best
    _, c, v1, v2 = solve(j, ts)
    u = tt - ts
    J = np.zeros((n, 4))  # d x / d (c, V1, V2, t_s)
    J[:, 0], J[:j, 1], J[j:, 2], J[:j, 3], J[j:, 3] = 1.0, u[:j], u[j:], -v1, -v2
    res = xx - c - J[:, 1] * v1 - J[:, 2] * v2
    se = errors(J, res, None if long_run is None else long_run[a:b])
    return Step(index=a + j, time=tc + ts, time_se=float(se[3]), v1=float(v1), v1_se=float(se[1]), v2=float(v2),
                v2_se=float(se[2]), rms=math.sqrt(float(res @ res) / n))


def joint_velocities(t, x, bounds, times, long_run=None) -> tuple[np.ndarray, np.ndarray]:
    """Velocities of every piece from one continuous piecewise-linear fit with its kinks at ``times`` (least
    squares, by normal equations summed in chunks: bounded memory), each with the standard error
    (``errors``) of a line through its own piece's samples."""
    tc, x0 = float(t[0]), float(x[0])
    knots = np.asarray(times, dtype=float) - tc

    def design(a, b):
        u = t[a:b] - tc
        return np.column_stack([np.ones_like(u), u] + [np.maximum(u - k, 0.0) for k in knots])

    n, m = len(t), len(times) + 2
    A, y = np.zeros((m, m)), np.zeros(m)
    for i in range(0, n, CHUNK):
        X = design(i, min(i + CHUNK, n))
        A += X.T @ X
        y += X.T @ (x[i:i + CHUNK] - x0)
    p = np.linalg.lstsq(A, y, rcond=None)[0]
    v = np.tril(np.ones((m - 1, m - 1))) @ p[1:]  # V_k = slope + the first k slope changes
    se = []
    for a, b in zip(bounds[:-1], bounds[1:]):
        res = x[a:b] - x0 - design(a, b) @ p
        se.append(errors(np.column_stack([np.ones(b - a), t[a:b] - tc]), res,
                         None if long_run is None else long_run[a:b])[1])
    return v, np.array(se)


# --- the segmentation ------------------------------------------------------------------------------
def segment(t: np.ndarray, x: np.ndarray, where: str = "record",
            line: Callable[[int], int] | None = None, unit: str = "") -> Segmentation:
    """Steps and jumps of the displacement record x(t) (module docstring); a one-line DatasetError starting
    with ``where`` and naming the line ``line(i)`` of sample i where the record is not straight pieces
    (displacements in it in ``unit``)."""
    t, x = np.asarray(t, dtype=float), np.asarray(x, dtype=float)
    n = len(t)
    line = line or (lambda i: i + 1)

    u = f" {unit}" if unit else ""

    def at(i: int) -> str:
        return f"line {line(i)} (t = {t[i]:.10g} s)"

    if n < 2 * MIN_PIECE:
        raise DatasetError(f"{where}: {n} samples; a velocity step needs at least {MIN_PIECE} on either side")
    penalty = 3.0 * math.log(n)
    g = grid(n)
    M, bps, s1, total = _partition(t, x, g, penalty)
    exact_to = least_count(x) if float(np.median(s1)) <= resolution(t, x) * (1 + 1e-9) and \
        sampled_exactly(x, last_digit(x)) else 0.0
    jumps, x = _jumps(t, x, M, (s1, total), bps, penalty, n)
    del M
    noise = StretchNoise(t, x, g, total)
    U = Moments(t, x, 1.0, g)
    cut = _merge(U, noise, [b for b in bps if b not in {j.index for j in jumps}], n)
    bounds = [0, *cut, n]
    for a, b in zip(bounds[:-1], bounds[1:]):
        if b - a < MIN_PIECE and (a == 0 or b == n):
            continue  # a change too near an end: refused below by what it is
        rms, level = math.sqrt(float(line_rss(U.between(a, b))) / (b - a)), noise(a, b)
        if rms > STRAIGHT * level:
            raise DatasetError(f"{where}: the displacement from {at(a)} to {at(b - 1)} is not a straight line: it "
                               f"strays {rms:.3g}{u} rms from its best line, {rms / level:.1f} times its noise "
                               f"({level:.3g}{u}); a velocity-step record is straight pieces of constant load-point "
                               "velocity (is the second column the load point's displacement?)")
    if not cut:
        v = np.polyfit(t - t[0], x, 1)[0]
        stitched = "".join(f"; a jump of {j.size:.4g}{u} at {at(j.index)} stitched" for j in jumps)
        raise DatasetError(f"{where}: no velocity step found: the displacement is one straight line within its noise "
                           f"({noise(0, n):.3g}{u}) from {at(0)} to {at(n - 1)}, at {v:.6g}{u or ' '}/s{stitched}")
    for a, b in zip(bounds[:-1], bounds[1:]):
        if b - a < MIN_PIECE:
            what = ("after the start of the record" if a == 0 else "before the end of the record" if b == n
                    else "after the change before it")
            s = b if a == 0 else a
            raise DatasetError(f"{where}: the velocity changes at {at(s)}, {b - a} sample{'s' * (b - a != 1)} "
                               f"{what}; a step needs at least {MIN_PIECE} samples of each velocity")
    long_run = noise_by_sample(t, x, cut)[2]  # again, now that the steps are known: a kink is not noise
    steps = [kink_fit(t, x, a, b, s, long_run) for a, s, b in zip(bounds[:-2], bounds[1:-1], bounds[2:])]
    bounds = [0, *(s.index for s in steps), n]  # the pieces now end at the kinks
    v, se = joint_velocities(t, x, bounds, [s.time for s in steps], long_run)
    if exact_to > 0:
        steps, se = _rounding_bounds(t, exact_to, steps, bounds, v, se)
    return Segmentation(steps=tuple(steps), jumps=tuple(jumps), bounds=tuple(bounds), velocities=tuple(v.tolist()),
                        velocities_se=tuple(se.tolist()), x=x, noise=float(np.median(total)), breakpoints=tuple(bps),
                        penalty=penalty, exact_to=exact_to)


def _rounding_bounds(t, q: float, steps: list, bounds: list, v: np.ndarray, se: np.ndarray):
    """Standard errors of a record without noise beyond its least count ``q``: no smaller than the error that a
    rounding of half a count at every sample after a step (or one count across a piece) makes, since rounding
    exact data errs alike at many samples: half a count over the change of velocity for a step's time, a count
    over the piece's duration for its velocity."""
    se = np.array([max(s, q / float(t[b - 1] - t[a])) for s, a, b in zip(se, bounds[:-1], bounds[1:])])
    steps = [attrs.evolve(st, time_se=max(st.time_se, 0.5 * q / abs(st.v2 - st.v1)), v1_se=max(st.v1_se, se[i]),
                          v2_se=max(st.v2_se, se[i + 1])) for i, st in enumerate(steps)]
    return steps, se


def _partition(t, x, g, penalty: float, passes: int = 4):
    """(moments, breakpoints, white and total noise by sample) of the optimal partition (move 2) weighted by the
    noise measured between its own breakpoints: first by the white noise (lag 1, which no change of slope
    inflates), then by the long-run noise of pseudo-residuals whose chords cross no breakpoint found, until the
    breakpoints settle (steps cannot pass for noise however many the record holds)."""
    n = len(t)
    s1, total, long_run = noise_by_sample(t, x)
    weights, bps = 1.0 / s1 ** 2, None
    for _ in range(passes):
        M = Moments(t, x, weights, g)
        found = pelt(M, penalty)
        if len(g) < n + 1:
            found = _refine(M, found, n)
        if found == bps:
            break
        bps = found
        s1, total, long_run = noise_by_sample(t, x, bps)
        weights = 1.0 / long_run
    return M, bps, s1, total


def _jumps(t, x, M: Moments, noise: tuple, bps: list[int], penalty: float, n: int):
    """The breakpoints that are jumps (move 3) and x with them stitched; ``noise``: the white and total noise by
    sample."""
    s1, total = noise
    phi = ar1_coefficient(s1, total)
    fine = [0, *bps, n]
    found = []
    for a, p, b in zip(fine[:-2], fine[1:-1], fine[2:]):
        if min(p - a, b - p) < 3:
            continue
        L, R = M.between(a, p), M.between(p, b)
        if jump_rss(L, R) - float(line_rss(L) + line_rss(R)) >= penalty:
            continue  # the slope changes
        v = (x[b - 1] - x[p] + x[p - 1] - x[a]) / (t[b - 1] - t[p] + t[p - 1] - t[a])  # the pieces' velocity
        d = np.mean(x[p:p + 3] - v * t[p:p + 3]) - np.mean(x[p - 3:p] - v * t[p - 3:p])
        if abs(d) > SHARP * shift_noise(total[p], phi[p]):
            found.append((a, p, b))
    jumps, x = [], x.copy()
    for a, p, b in found:  # the offset of parallel lines through [a, p) and [p, b)
        u = t[a:b] - t[p]
        X = np.column_stack([np.ones(b - a), (np.arange(a, b) >= p).astype(float), u])
        coef, *_ = np.linalg.lstsq(X, x[a:b], rcond=None)
        se = errors(X, x[a:b] - X @ coef)[1]
        x[p:] -= coef[1]
        jumps.append(Jump(index=p, size=float(coef[1]), size_se=float(se)))
    return jumps, x


def _merge(U: Moments, noise: StretchNoise, bps: list[int], n: int) -> list[int]:
    """Merge neighbouring pieces, the straightest union first, while each strays from the union's line by at
    most MERGE times their noise (move 4); the breakpoints left."""
    bounds = [0, *bps, n]

    def score(a, p, b):  # the larger rms of either piece about the union's line, over the noise
        level = math.sqrt(((p - a) * noise(a, p, 4) ** 2 + (b - p) * noise(p, b, 4) ** 2) / (b - a))
        line = line_params(U.between(a, b))
        worst = max(rss_about(U.between(a, p), line) / (p - a), rss_about(U.between(p, b), line) / (b - p))
        return math.sqrt(worst) / max(level, 1e-300)

    scores = [score(*abc) for abc in zip(bounds[:-2], bounds[1:-1], bounds[2:])]
    while scores and min(scores) <= MERGE:
        i = int(np.argmin(scores))
        del bounds[i + 1], scores[i]
        if i > 0:
            scores[i - 1] = score(*bounds[i - 1:i + 2])
        if i < len(scores):
            scores[i] = score(*bounds[i:i + 3])
    return bounds[1:-1]
