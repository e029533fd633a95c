"""Goodness of fit: are a fitted law's residuals what the dataset's noise would leave?

Two tests per fitted dataset, on the normalized residuals z = (model - data) / sigma:

* chi-square: p = P(chi2 with n - k degrees of freedom >= observed chi2) where the dataset's sigma
  is known (measured). Where sigma is estimated from the data (io/noise.py, nu effective degrees of
  freedom) the estimate's own uncertainty is carried in: the F test p = P(F(n - k, nu) >= chi2 / (n - k))
  (conservative: residuals and estimate share the noise), sharpened where it does not already reject
  by the exact null of both from common noise (``noise.ratio_pvalue``, done by the fit).
* residual structure: the Wald-Wolfowitz runs test on the signs of z (zeros dropped), one-sided:
  a law that misses the data's shape leaves long runs of one sign (too few runs). Normal
  approximation with continuity correction; needs at least RUNS_MIN nonzero residuals, else NaN.
  The lag-1 autocorrelation r1 of z is reported beside it (one-sided p from r1 sqrt(n) ~ N(0, 1)),
  not used by the rule.

* whiteness (AR(1) noise only, ``inference.noise.ar1``): the Ljung-Box test of the prewhitened residuals'
  autocorrelations at lags 1 to WHITE_LAGS (degrees of freedom WHITE_LAGS minus the fitted coefficients): the
  noise model says they are white; a law that misses the data's shape, or noise that is not AR(1), leaves them
  correlated. Then the three tests share the family-wise level, each at FITS_LEVEL / 3.

Rule (``FITS_LEVEL`` = 0.01, family-wise over the two tests): a candidate fits a dataset when
both p-values are at least ``TEST_LEVEL`` = 0.005 (Bonferroni over the two tests). The level keeps the false alarm rate of a true law low on the handful of
built-in known-truth sets while a misfit of several sigma over tens of points fails by orders of
magnitude. Over a group of m datasets the p-values are Bonferroni-adjusted (m times the smallest,
capped at 1), so the group rule is the same rule at the same 1% family-wise level.
"""
from __future__ import annotations

import math

import attrs
import numpy as np

FITS_LEVEL = 0.01  # family-wise level of the fit tests (chi-square or F, and runs) on one dataset or group
TEST_LEVEL = FITS_LEVEL / 2  # each of the two tests (Bonferroni)
RUNS_MIN = 10
WHITE_LAGS = 20  # lags of the whiteness test of prewhitened residuals
SHARPEN_BELOW = 1e-3  # an F p-value (conservative) below this already rejects: no sharper p-value is needed


@attrs.frozen
class Goodness:
    """Goodness of fit of one candidate on one dataset (or a group: Bonferroni-adjusted p-values)."""

    likelihood: str  # 'known' | 'estimated' | 'mixed' | 'none' (no valid likelihood: a smoothed derived series)
    chi2_p: float  # chi-square (known sigma) or F (estimated sigma) p-value; NaN without a likelihood
    runs_p: float  # NaN when too few nonzero residuals
    runs: int  # observed runs of residual signs (group: summed)
    runs_expected: float
    lag1: float  # lag-1 autocorrelation of the normalized residuals (group: the largest)
    lag1_p: float
    fits: bool | None  # None when no test could be made
    reason: str  # one phrase: why it fits or does not
    members: int = 1  # datasets combined (p-values Bonferroni-adjusted when more than one)
    white_p: float = math.nan  # Ljung-Box p of prewhitened residuals (AR(1) noise only; NaN otherwise)
    #: Under the data's AR(p) noise model (``law_fit``): the law-fit test of bands after the step, its band and
    #: statistic, whether the noise model whitens the residuals, and that test in words.
    band_p: float = math.nan
    band: str = ""
    band_what: str = ""
    noise_ok: bool | None = None
    whiteness_text: str = ""

    def as_dict(self) -> dict:
        return attrs.asdict(self)

    @property
    def text(self) -> str:
        """'chi2 p = 0.41, runs p = 0.62' (the numbers the rule uses)."""
        parts = []
        if math.isfinite(self.chi2_p):
            parts.append(f"chi2 p = {_p(self.chi2_p)}")
        if math.isfinite(self.runs_p):
            parts.append(f"runs p = {_p(self.runs_p)}")
        if math.isfinite(self.band_p):
            parts.append(f"law fit (bands after the step) p = {_p(self.band_p)}: {self.band_what} {self.band}")
        if math.isfinite(self.white_p):
            parts.append(f"whiteness p = {_p(self.white_p)}" + (" (the noise model's test, not the law's)"
                                                                 if self.noise_ok is not None else ""))
        if math.isfinite(self.lag1):
            parts.append(f"lag-1 r = {self.lag1:+.2f}")
        text = ", ".join(parts) or "no test possible"
        return text + (f"; p Bonferroni-adjusted over {self.members} datasets" if self.members > 1 else "")

    @property
    def short(self) -> str:
        """'fits: chi2 p = 0.96' / 'fails: runs p = 8e-10': the verdict and the p-value closest to failing."""
        if self.noise_ok is not None:  # the data's AR(p) model: the law-fit test alone decides
            ps = [("bands", self.band_p)] if math.isfinite(self.band_p) else []
        else:
            ps = [(name, p) for name, p in (("χ²" if self.likelihood != "estimated" else "χ²/σ̂²", self.chi2_p),
                                            ("runs", self.runs_p), ("whiteness", self.white_p)) if math.isfinite(p)]
        if self.fits is None or not ps:
            return "not testable"
        name, p = min(ps, key=lambda x: x[1])
        return f"{'fits' if self.fits else 'fails'}: {name} p {'' if p == 0 else '= '}{p_short(p)}"


def p_short(p: float) -> str:
    """A p-value in a few characters: 0.96, 0.012, 8e-10 (two figures, one below 0.001), < 1e-300."""
    if p == 0:
        return "< 1e-300"  # below the floating-point range
    return f"{p:.2g}" if p >= 1e-3 else f"{p:.0e}".replace("e-0", "e-")


def _p(p: float) -> str:
    return f"{p:.2g}" if p >= 1e-3 else f"{p:.1e}"


# The p-values below call the special functions scipy.stats' chi2.sf, norm.cdf and norm.sf evaluate
# (chdtrc, ndtr), without the distribution objects' argument handling (20 us a call, three calls per fit;
# the same numbers, tests/test_verdicts.py).
def chi2_pvalue(chisqr: float, dof: int) -> float:
    from scipy.special import chdtrc

    return float(chdtrc(dof, chisqr)) if dof > 0 and math.isfinite(chisqr) else math.nan


def runs_test(z: np.ndarray) -> tuple[int, float, float]:
    """(runs, expected runs, one-sided p of too few runs) of the signs of z; p NaN if too few values."""
    from scipy.special import ndtr

    s = np.sign(np.asarray(z, dtype=float))
    s = s[s != 0]
    n1, n2 = int(np.sum(s > 0)), int(np.sum(s < 0))
    n = n1 + n2
    runs = int(1 + np.sum(s[1:] != s[:-1])) if n else 0
    if n < RUNS_MIN:
        return runs, math.nan, math.nan
    if n1 == 0 or n2 == 0:  # every residual on one side: as structured as residuals get
        return runs, 1.0, 0.0
    mean = 1 + 2 * n1 * n2 / n
    var = 2 * n1 * n2 * (2 * n1 * n2 - n) / (n * n * (n - 1))
    zstat = (runs - mean + 0.5) / math.sqrt(var) if var > 0 else 0.0
    return runs, mean, float(ndtr(zstat))


def lag1(z: np.ndarray) -> tuple[float, float]:
    """Lag-1 autocorrelation of z (about its mean) and its one-sided p (positive correlation)."""
    from scipy.special import ndtr

    z = np.asarray(z, dtype=float)
    if z.size < 3:
        return math.nan, math.nan
    d = z - z.mean()
    den = float(d @ d)
    if den <= 0:
        return math.nan, math.nan
    r = float(d[1:] @ d[:-1]) / den
    return r, float(ndtr(-(r * math.sqrt(z.size))))


def f_pvalue(chisqr: float, dof: int, df_sigma: float) -> float:
    """P(F(dof, df_sigma) >= chisqr / dof): the chi-square test when sigma^2 is an estimate with df_sigma
    degrees of freedom (the chi-square p as df_sigma -> infinity)."""
    from scipy.special import fdtrc

    if not math.isfinite(df_sigma):
        return chi2_pvalue(chisqr, dof)
    return float(fdtrc(dof, df_sigma, chisqr / dof)) if dof > 0 and math.isfinite(chisqr) else math.nan


def ljung_box(z: np.ndarray, fitted: int, lags: int = WHITE_LAGS) -> float:
    """p of the Ljung-Box test that z is white: Q = n (n + 2) sum_k r_k^2 / (n - k), k = 1..lags, against
    chi-square with lags - fitted degrees of freedom (``fitted``: coefficients of the noise model); NaN when too
    short."""
    z = np.asarray(z, dtype=float)
    n = z.size
    if n < 5 * lags or lags <= fitted:
        return math.nan
    d = z - z.mean()
    den = float(d @ d)
    if den <= 0:
        return math.nan
    q = sum(float(d[k:] @ d[:-k]) ** 2 / den ** 2 / (n - k) for k in range(1, lags + 1)) * n * (n + 2)
    return chi2_pvalue(q, lags - fitted)


def goodness(z: np.ndarray, k: int, likelihood: str, df_sigma: float = math.inf, chi_p: float | None = None,
             white_p: float = math.nan) -> Goodness:
    """Goodness of one fitted dataset from its normalized residuals z, k fitted parameters and the
    degrees of freedom of its sigma (infinite when measured); chi_p: the fit test's p where the caller
    has a sharper one (``noise.ratio_pvalue``); white_p: the whiteness test's p of prewhitened residuals
    (AR(1) noise), which joins the rule."""
    z = np.asarray(z, dtype=float)
    if likelihood == "none":
        return Goodness("none", math.nan, math.nan, 0, math.nan, math.nan, math.nan, None,
                        "no test: no valid likelihood (a smoothed, derived series or a noise-free curve)")
    if chi_p is None:
        chi_p = f_pvalue(float(z @ z), z.size - k, df_sigma if likelihood == "estimated" else math.inf)
    runs, expected, runs_p = runs_test(z)
    r1, r1_p = lag1(z)
    return _decide(likelihood, chi_p, runs_p, runs, expected, r1, r1_p, white_p)


def law_fit(z: np.ndarray, white_p: float, white_text: str, bands) -> Goodness:
    """Goodness under the data's AR(p) noise model (its innovation level profiled: no chi-square test): the law
    fits unless the band test (``noise.misfit.BandTest``, None: not made) finds structure after a step below
    FITS_LEVEL; the whiteness of the whitened residuals z is the noise model's test, reported apart."""
    z = np.asarray(z, dtype=float)
    runs, expected, runs_p = runs_test(z)
    r1, r1_p = lag1(z)
    noise_ok = bool(white_p >= FITS_LEVEL) if math.isfinite(white_p) else None
    band_p = bands.p if bands is not None else math.nan
    extra = dict(white_p=white_p, band_p=band_p, band=bands.band if bands is not None else "",
                 band_what=bands.what if bands is not None else "", noise_ok=noise_ok, whiteness_text=white_text)
    if not math.isfinite(band_p):
        return Goodness("estimated", math.nan, runs_p, runs, expected, r1, r1_p, None,
                        "no band after a step could be tested", **extra)
    if band_p < FITS_LEVEL:
        why = (f"structure after the step beyond the noise: the whitened residuals' {bands.what} over {bands.band}, "
               f"p = {_p(band_p)} < {FITS_LEVEL:g} against the record's steady state")
        return Goodness("estimated", math.nan, runs_p, runs, expected, r1, r1_p, False, why, **extra)
    why = f"no structure after the step beyond the noise (bands p = {_p(band_p)} >= {FITS_LEVEL:g})"
    return Goodness("estimated", math.nan, runs_p, runs, expected, r1, r1_p, True, why, **extra)


def _decide(likelihood, chi_p, runs_p, runs, expected, r1, r1_p, white_p=math.nan) -> Goodness:
    tests = [(name, p) for name, p in (("chi-square" if likelihood != "estimated" else "chi-square at estimated sigma", chi_p), ("runs test", runs_p),
                                       ("whiteness test of the prewhitened residuals", white_p)) if math.isfinite(p)]
    level = TEST_LEVEL if not math.isfinite(white_p) else FITS_LEVEL / 3
    done = dict(white_p=white_p)
    if not tests:
        return Goodness(likelihood, chi_p, runs_p, runs, expected, r1, r1_p, None, "no test possible (too few points)", **done)
    failed = [f"{name} p = {_p(p)} < {level:.2g}" for name, p in tests if p < level]
    if failed:
        why = "; ".join(failed)
        if "runs" in why:
            why += f" ({runs} runs of residual signs where {expected:.0f} are expected: systematic misfit)"
        return Goodness(likelihood, chi_p, runs_p, runs, expected, r1, r1_p, False, why, **done)
    why = " and ".join(f"{name} p >= {level:.2g}" for name, _ in tests)
    if len(tests) > 1:
        why += f" (each at {level:.2g}: {FITS_LEVEL:g} family-wise)"
    return Goodness(likelihood, chi_p, runs_p, runs, expected, r1, r1_p, True, why, **done)


def combine(members: list[Goodness]) -> Goodness:
    """A group's goodness: Bonferroni-adjusted p-values (m times the smallest, at most 1)."""
    if len(members) == 1:
        return members[0]
    m = len(members)
    kinds = {g.likelihood for g in members}
    if "none" in kinds:
        return goodness(np.zeros(0), 0, "none")

    def adjusted(ps):
        ps = [p for p in ps if math.isfinite(p)]
        return min(1.0, m * min(ps)) if ps else math.nan

    if all(g.noise_ok is not None for g in members):  # the data's AR(p) models: the band tests decide
        from types import SimpleNamespace

        worst = min(members, key=lambda g: g.band_p if math.isfinite(g.band_p) else math.inf)
        bands = SimpleNamespace(p=adjusted(g.band_p for g in members), band=worst.band, what=worst.band_what)
        texts = "; ".join(g.whiteness_text for g in members if g.whiteness_text)
        return attrs.evolve(law_fit(np.zeros(0), adjusted(g.white_p for g in members), texts, bands), members=m)
    lags = [(g.lag1, g.lag1_p) for g in members if math.isfinite(g.lag1)]
    r1, r1_p = max(lags) if lags else (math.nan, math.nan)
    return attrs.evolve(_decide(kinds.pop() if len(kinds) == 1 else "mixed", adjusted(g.chi2_p for g in members),
                   adjusted(g.runs_p for g in members), sum(g.runs for g in members),
                   sum(g.runs_expected for g in members if math.isfinite(g.runs_expected)), r1, r1_p,
                   adjusted(g.white_p for g in members)), members=m)
