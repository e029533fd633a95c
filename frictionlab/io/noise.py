"""Noise from the data alone, without any friction law: what a dataset with ``[noise] kind = "estimated"``
(or no ``[noise]`` table) is fitted with.

* Replicates (rows with the same conditions, e.g. one incidence angle measured several times): the
  pooled within-condition variance, sum over conditions of sum (y - mean)^2 / sum (n_c - 1), with
  sum (n_c - 1) degrees of freedom.
* Otherwise Gasser, Sroka and Jennen-Steinmetz (1986, Biometrika 73): for points in order of x (time,
  or incidence within one speed) the pseudo-residuals e_i = a_i y_{i-1} + b_i y_{i+1} - y_i,
  a_i = (x_{i+1} - x_i) / (x_{i+1} - x_{i-1}), b_i = 1 - a_i, vanish on any straight line, so
  sigma^2 = mean of e_i^2 / (a_i^2 + b_i^2 + 1) carries the noise and only the curvature of the
  signal between neighbours (small when the sampling resolves the curve; it inflates sigma, so
  the tests that use it err on the side of accepting a law).

The estimate sigma^2 = y' Q y is a quadratic form in the data; with pure noise its effective degrees
of freedom are nu = tr(Q)^2 / tr(Q^2) (Satterthwaite), about 0.51 n for evenly spaced points. A test
that uses sigma-hat carries nu: the goodness of fit is an F test with (n - k, nu) degrees of freedom.
The fit's residuals and sigma-hat come from the same noise, so that F test is conservative; where it
does not already reject, ``ratio_pvalue`` gives the exact p of chi2 / (n - k) under the fitted law
(linearized at the fit) by simulating both quadratic forms from common noise draws.
"""
from __future__ import annotations

import math

import attrs
import numpy as np

from ..core.errors import DatasetError

MIN_DF = 2.0  # fewer effective degrees of freedom give no usable estimate
#: What a dataset says about its noise: 'known' (sigma measured and declared: the likelihood uses it),
#: 'estimated' (sigma estimated from the data alone, without any law: ``noise.py``; declared values,
#: if any, are ignored) or 'none' (a noise-free reconstruction: the declared values are the stated
#: precision of the numbers it was drawn through). No [noise] table means estimated; the old
#: 'assumed' (a guessed sigma) is read as estimated: a guess is never used.
NOISE_KINDS = ("known", "estimated", "none")
NOISE_ALIASES = {"assumed": "estimated"}
#: Numbers a paper states about an impact's spin, and their SI units: the peak spin, its time, the spin
#: at the end of contact (t_c, the scene's contact time) and the largest rotation angle.
STATED = {"omega_peak": "rad/s", "t_peak": "s", "omega_end": "rad/s", "theta_max": "rad"}



@attrs.frozen
class NoiseEstimate:
    """sigma [the column's SI unit], its effective degrees of freedom, and how it was obtained."""

    sigma: float
    df: float
    method: str  # 'replicates' | 'GSJS'
    rows: np.ndarray | None = attrs.field(default=None, eq=False, repr=False)  # GSJS: point indices (m x 3)
    weights: np.ndarray | None = attrs.field(default=None, eq=False, repr=False)  # GSJS: unit-norm weights (m x 3)
    labels: np.ndarray | None = attrs.field(default=None, eq=False, repr=False)  # replicates: condition per point

    def variance(self, E: np.ndarray) -> np.ndarray:
        """sigma-hat^2 of each row of E (draws x points, in the dataset's row order)."""
        if self.labels is not None:
            out = np.zeros(E.shape[0])
            for g in np.unique(self.labels):
                block = E[:, self.labels == g]
                out += np.sum((block - block.mean(axis=1, keepdims=True)) ** 2, axis=1)
            return out / self.df
        e = np.einsum("zmk,mk->zm", E[:, self.rows], self.weights)
        return np.mean(e * e, axis=1)


def gsjs(x: np.ndarray, y: np.ndarray, segments: np.ndarray | None = None) -> NoiseEstimate | None:
    """The Gasser-Sroka-Jennen-Steinmetz estimate of y's noise, points ordered by x (increasing within
    each segment label; segments: a label per point, None for one series). None without a triple of
    neighbours spanning a positive interval."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    seg = np.zeros(x.size, dtype=int) if segments is None else np.asarray(segments)
    i = np.arange(1, x.size - 1)
    i = i[(seg[i - 1] == seg[i]) & (seg[i + 1] == seg[i]) & (x[i + 1] > x[i - 1])] if i.size else i
    if not i.size:
        return None
    a = (x[i + 1] - x[i]) / (x[i + 1] - x[i - 1])
    W = np.column_stack([a, -np.ones_like(a), 1.0 - a]) / np.sqrt(a * a + (1 - a) ** 2 + 1)[:, None]
    I = np.column_stack([i - 1, i, i + 1])  # noqa: E741 (the points each pseudo-residual combines)
    e = np.sum(W * y[I], axis=1)
    m = i.size
    # tr(Q) and tr(Q^2) of Q = C'C / m (C: the m x n pseudo-residual weights; each row has unit norm, so
    # tr(Q) = 1); tr(Q^2) = |C C'|_F^2 / m^2
    tr2 = _frobenius2(_band(W, I))
    return NoiseEstimate(math.sqrt(float(e @ e) / m), m * m / tr2 if tr2 > 0 else 0.0, "GSJS", rows=I, weights=W)


def _band(W: np.ndarray, I: np.ndarray) -> dict[int, np.ndarray]:  # noqa: E741
    """K = C C' of pseudo-residual rows (weights W on the points I, each m x 3) as its diagonals: d -> K(j, j + d)
    for j = 0 .. m - 1, d = 0, 1, 2 (zero where j + d is outside; rows overlap only where their triples share a
    point, so K is a band)."""
    m = I.shape[0]
    band = {0: np.sum(W * W, axis=1)}
    Wt, It = np.ascontiguousarray(W.T), np.ascontiguousarray(I.T)
    for d in (1, 2):
        dot = np.zeros(m)
        for a in range(I.shape[1]):
            for b in range(I.shape[1]):
                same = It[a, : m - d] == It[b, d:]
                if same.any():
                    dot[: m - d] += np.where(same, Wt[a, : m - d] * Wt[b, d:], 0.0)
        band[d] = dot
    return band


def _frobenius2(band: dict[int, np.ndarray]) -> float:
    """tr(K^2) = |K|_F^2 of the symmetric band ``band`` (``_band``)."""
    return float(band[0] @ band[0]) + 2.0 * sum(float(band[d] @ band[d]) for d in (1, 2))


def replicate_spread(keys: list, y: np.ndarray) -> NoiseEstimate | None:
    """Pooled within-condition spread of y over rows with equal ``keys``; None without replicates."""
    y = np.asarray(y, dtype=float)
    groups: dict = {}
    for i, k in enumerate(keys):
        groups.setdefault(k, []).append(i)
    ss, df = 0.0, 0
    for idx in groups.values():
        if len(idx) > 1:
            v = y[idx]
            ss += float(np.sum((v - v.mean()) ** 2))
            df += len(idx) - 1
    if df < MIN_DF:
        return None
    labels = np.zeros(len(keys), dtype=int)
    for j, idx in enumerate(groups.values()):
        labels[idx] = j
    return NoiseEstimate(math.sqrt(ss / df), float(df), "replicates", labels=labels)


def estimate(columns: dict, col: str) -> NoiseEstimate | None:
    """The noise of column ``col`` of a dataset's SI columns: from replicates if the conditions repeat,
    else GSJS along t (a time series) or along incidence within each speed (one impact per row).
    None when the data give no estimate (too few points, or a series without noise: sigma 0)."""
    y = columns[col]
    if "t" in columns:
        est = gsjs(columns["t"], y)
    else:
        conds = [c for c in ("speed", "incidence", "spin") if c in columns and c != col]
        if not conds:
            return None
        keys = list(zip(*(np.round(columns[c], 12).tolist() for c in conds)))
        est = replicate_spread(keys, y)
        if est is None:
            order = np.lexsort([columns[c] for c in reversed(conds)])
            along = columns[conds[-1]][order] if len(conds) > 1 else columns[conds[0]][order]
            seg = (np.round(columns[conds[0]][order], 9) if len(conds) > 1 else None)
            est = gsjs(along, y[order], seg)
            if est is not None:  # back to the dataset's row order
                est = attrs.evolve(est, rows=order[est.rows])
    if est is None or est.df < MIN_DF or not est.sigma > 0 or not math.isfinite(est.sigma):
        return None
    return est


DRAWS = 4000  # noise draws of ``ratio_pvalue``
#: Floats of one chunk of ``ratio_pvalue``'s draws (draws x points): its memory is bounded by this, not by DRAWS x n.
CHUNK_FLOATS = 2_000_000


def ratio_pvalue(est: NoiseEstimate, chisqr: float, J: np.ndarray, seed: int = 0) -> float:
    """P(chi2* / (n - k) >= chisqr / (n - k)) where chi2* is the fit's chi-square at sigma-hat on data of the
    fitted law plus noise, linearized at the fit: residuals e - P e (P the projection onto the columns
    of J, the weighted Jacobian of this dataset's points, n x k) over sigma-hat^2 of the same e.
    chisqr is at sigma-hat. Monte Carlo with DRAWS draws, made in chunks of at most CHUNK_FLOATS numbers (the same
    draws as one block): its floor is 1 / (DRAWS + 1)."""
    n = J.shape[0]
    rng = np.random.default_rng(seed)
    Qj = _column_basis(J)
    hits = 0
    step = max(1, min(DRAWS, CHUNK_FLOATS // max(n, 1)))
    for start in range(0, DRAWS, step):
        E = rng.standard_normal((min(step, DRAWS - start), n))
        E_res = E - (E @ Qj) @ Qj.T if Qj.shape[1] else E
        ratio = np.sum(E_res * E_res, axis=1) / est.variance(E)
        hits += int(np.sum(ratio >= chisqr))
    return (1.0 + hits) / (DRAWS + 1.0)


def _column_basis(J: np.ndarray) -> np.ndarray:
    """An orthonormal basis of the columns of J that matter (singular values above 1e-9 of the largest)."""
    if not J.size:
        return np.zeros((J.shape[0], 0))
    U, s, _ = np.linalg.svd(J, full_matrices=False)
    return U[:, s > 1e-9 * s.max()] if s.size and s.max() > 0 else U[:, :0]


def ratio_pvalue_moments(est: NoiseEstimate, chisqr: float, J: np.ndarray) -> float | None:
    """``ratio_pvalue`` without simulation, for a GSJS estimate: with white noise e ~ N(0, I) the statistic exceeds
    c = chisqr when Q = e' (I - P - c G) e >= 0, G = C'C / m the estimate's quadratic form (C: its m pseudo-residual
    rows). Q's first three cumulants are traces (2^(j-1) (j-1)! tr(M^j)), computed in O(n k) time and memory from
    the five diagonals of the band C C' and the columns of J; P(Q >= 0) follows from Pearson's three-moment
    chi-square approximation (a shifted and scaled chi-square with Q's mean, variance and skewness). None for an
    estimate from replicates."""
    from scipy.special import chdtr, chdtrc, ndtr

    if est.rows is None or est.weights is None:
        return None
    n = J.shape[0]
    I, W = est.rows, est.weights  # noqa: E741 (the points each pseudo-residual combines, and its weights)
    m = I.shape[0]
    Qj = _column_basis(J)
    p = Qj.shape[1]
    tr_PG = tr_PG2 = 0.0
    for c in range(p):  # C q and C'C q / m of each basis column q, one at a time
        Cq = np.sum(W * Qj[I, c], axis=1)
        tr_PG += float(Cq @ Cq) / m
        Gq = np.bincount(I.ravel(), weights=(W * Cq[:, None]).ravel(), minlength=n) / m
        tr_PG2 += float(Gq @ Gq)
    band = _band(W, I)  # K = C C'
    tr_K2 = _frobenius2(band)

    diag = {}  # d -> K(i, i + d) for i = 0 .. m - 1 (zero where i + d is outside)
    for d in range(-2, 3):
        if d >= 0:
            diag[d] = band[d]
        else:
            diag[d] = np.zeros(m)
            diag[d][-d:] = band[-d][: m + d]

    tr_K3 = 0.0
    for d1 in range(-2, 3):
        for d2 in range(-2, 3):
            d3 = -(d1 + d2)
            if abs(d3) > 2:
                continue
            lo, hi = max(0, -d1, -d1 - d2), min(m, m - d1, m - d1 - d2)
            if hi > lo:
                tr_K3 += float(np.dot(diag[d1][lo:hi] * diag[d2][lo + d1:hi + d1], diag[d3][lo + d1 + d2:hi + d1 + d2]))
    tr_G2, tr_G3 = tr_K2 / m ** 2, tr_K3 / m ** 3
    c = float(chisqr)
    t1 = (n - p) - c
    t2 = (n - p) - 2 * c * (1 - tr_PG) + c * c * tr_G2
    t3 = (n - p) - 3 * c * (1 - tr_PG) + 3 * c * c * (tr_G2 - tr_PG2) - c ** 3 * tr_G3
    mean, var, k3 = t1, 2 * t2, 8 * t3
    if not var > 0:
        return None
    sd = math.sqrt(var)
    skew = k3 / var ** 1.5
    if abs(skew) < 1e-8:
        return float(ndtr(mean / sd))
    d = 8.0 / (skew * skew)
    edge = max(d - math.copysign(1.0, skew) * mean * math.sqrt(2 * d) / sd, 0.0)  # chi-square lives on x >= 0
    return float(chdtrc(d, edge)) if skew > 0 else float(chdtr(d, edge))


# --- the [noise] and [stated] tables of a dataset TOML ----------------------------------------------
def stated_table(spec: dict, path, kind: str, noise_kind: str, quantity) -> dict:
    """[stated] (``spec``): name -> (value, precision) in SI; only an impact's noise-free reconstruction has
    one. quantity(text, si_unit, where) parses a quantity."""
    if spec and (kind != "impact" or noise_kind != "none"):
        raise DatasetError(f"{path}: [stated] belongs to an impact reconstruction with [noise] kind = 'none'")
    out = {}
    for name, pair in spec.items():
        if name not in STATED:
            raise DatasetError(f"{path}: stated.{name} is not a stated number frictionlab can predict "
                               f"({', '.join(STATED)})")
        if not (isinstance(pair, list) and len(pair) == 2):
            raise DatasetError(f"{path}: stated.{name} must be [\"value\", \"precision\"], e.g. [\"6700 rpm\", \"100 rpm\"]")
        value, prec = (quantity(x, STATED[name], f"{path}: stated.{name}") for x in pair)
        if not prec > 0:
            raise DatasetError(f"{path}: stated.{name}: the precision must be positive, got {pair[1]!r}")
        out[name] = (value, prec)
    return out


def noise_table(spec: dict, path, observable: str, columns: dict, si_of) -> tuple[dict, str, dict, str]:
    """(sigma by column, kind, NoiseEstimate by estimated column, note) from the [noise] table ``spec``;
    si_of(column, text, where) parses a declared value into SI."""
    spec = dict(spec)
    values = [k for k in spec if k != "kind"]
    if "kind" not in spec and values:  # a sigma whose use is not declared would be silently ignored
        raise DatasetError(f"{path}: [noise] gives {', '.join(values)} without kind: add kind = \"known\" (the "
                           "values are a measured sigma, used as given) or kind = \"estimated\" (sigma from the "
                           "data alone; the values are then not used)")
    kind = spec.pop("kind", "estimated")
    if not isinstance(kind, str):
        raise DatasetError(f"{path}: noise.kind must be a string, one of {', '.join(NOISE_KINDS)}")
    alias = NOISE_ALIASES.get(kind)
    kind = alias or kind
    if kind not in NOISE_KINDS:
        raise DatasetError(f"{path}: noise.kind = {kind!r}, expected one of {', '.join(NOISE_KINDS)} "
                           "(known: sigma measured; estimated: from the data; none: a noise-free reconstruction)")
    declared = {}
    for col, value in spec.items():
        if col not in columns:
            raise DatasetError(f"{path}: noise.{col} names no declared column")
        declared[col] = si_of(col, value, f"{path}: noise.{col}")
        if not declared[col] > 0:
            raise DatasetError(f"{path}: noise.{col} must be positive, got {value!r}")
    if kind == "none":
        return declared, kind, {}, ("a noise-free reconstruction; laws are compared on the numbers it was "
                                    "drawn through, at their stated precision ([stated]); the curve is for figures")
    if kind == "known":
        if observable not in declared:
            raise DatasetError(f"{path}: [noise] kind = 'known' must give the measured sigma of the observable, "
                               f"e.g. {observable} = '100 rpm'")
        return declared, kind, {}, "declared sigma, measured (kind = known)"
    noise, ests = {}, {}
    for col in columns:
        if col in ("t", "speed", "incidence"):
            continue
        est = estimate(columns, col)
        if est is not None:
            noise[col], ests[col] = est.sigma, est
    if observable not in noise:
        raise DatasetError(f"{path}: the noise of '{observable}' cannot be estimated from the data (too few "
                           f"points, or no scatter): declare it, [noise] kind = 'known', {observable} = '...'")
    method = {"GSJS": "Gasser-Sroka-Jennen-Steinmetz differences", "replicates": "the spread of replicates"}
    how = method[ests[observable].method]
    why = (f"[noise] kind = '{next(k for k, v in NOISE_ALIASES.items() if v == kind)}' is read as estimated: a "
           "guessed sigma is never used" if alias else "no measured sigma declared")
    ignored = f"; the declared {observable} sigma is ignored" if observable in declared else ""
    note = f"estimated from the data by {how} ({ests[observable].df:.0f} effective degrees of freedom): {why}{ignored}"
    return noise, kind, ests, note
