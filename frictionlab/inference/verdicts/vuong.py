"""Which of two laws is closer to the data when neither need be true: Vuong's (1989, Econometrica 57, 307)
non-nested likelihood-ratio test, with a Newey-West (1987) long-run variance for serially correlated records.

l_i = ln f_A(y_i | past) - ln f_B(y_i | past), the pointwise log-likelihood differences of the two fits, each
under its own noise model (its whitened residual and level, ``velstep_result``: the same likelihood as the AIC,
BIC, Akaike weights and -2 ln L of the ranking, so every measure orders the two laws the same way). The statistic

    z = (sum l_i - (k_A - k_B)) / sqrt(n s^2)

with the AIC-type correction for the parameters counted by the likelihood (k) and s^2 the Bartlett-weighted
(Newey-West) long-run variance of l_i at NW_LAGS(n) = floor(4 (n / 100)^(2/9)) lags. Null: both laws are equally
close to the process that made the data (in Kullback-Leibler distance); z ~ N(0, 1). Two-sided at LEVEL: "B is
closer (p = ...)" or "equally close at this noise (p = ...)". Its size and power are measured on synthetic steps
(``benchmarks/calibration_vuong.py``).
"""
from __future__ import annotations

import math

import attrs
import numpy as np

from ..noise.hac import long_run_covariance, nw_lags

#: Two-sided level of the test.
LEVEL = 0.05


def long_run_variance(d, lags: int | None = None) -> float:
    """The Newey-West long-run variance of d (mean removed): gamma_0 + 2 sum_j (1 - j / (L + 1)) gamma_j."""
    return float(long_run_covariance(d, lags)[0, 0])


@attrs.frozen
class VuongResult:
    law_a: str
    law_b: str
    z: float  # > 0: A closer
    p: float  # two-sided
    n: int
    lags: int
    lr: float  # sum l_i - (k_A - k_B)

    @property
    def closer(self) -> str:
        """The closer law where the test rejects equal closeness at LEVEL, else ''."""
        if not self.p < LEVEL:
            return ""
        return self.law_a if self.z > 0 else self.law_b

    @property
    def text(self) -> str:
        """'rate-state-slip is closer (p = 0.003)' or 'equally close at this noise (p = 0.4)'."""
        p = f"{self.p:.2g}" if self.p >= 1e-3 else f"{self.p:.1e}"
        tail = (f"Vuong's test, z = {self.z:+.2f} over {self.n} samples, Newey-West variance over {self.lags} lags")
        if self.closer:
            return f"{self.closer} is closer (p = {p}; {tail})"
        return f"{self.law_a} and {self.law_b} are equally close at this noise (p = {p}; {tail})"


def pointwise(fit) -> np.ndarray | None:
    """The per-sample log-likelihoods of a single-dataset fit: those it stored (a velocity-step fit, its noise
    model's), else independent Gaussian terms at the likelihood's sigma; None without a likelihood."""
    if not fit.ok or len(fit.per_dataset) != 1:
        return None
    d = fit.per_dataset[0]
    stored = getattr(d, "loglik", None)
    if stored is not None:
        return np.asarray(stored, dtype=float)
    if fit.stats is None or fit.stats.likelihood not in ("known", "estimated"):
        return None
    sigma = np.broadcast_to(np.asarray(d.target.sigma, dtype=float), np.shape(d.target.y))
    z = (np.asarray(d.model, dtype=float) - np.asarray(d.target.y, dtype=float)) / sigma
    return -0.5 * (z * z + np.log(2 * math.pi * sigma ** 2))


def vuong(fit_a, fit_b) -> VuongResult | None:
    """Vuong's test of two fits of one dataset (module docstring); None where either has no pointwise likelihood
    or they differ in samples."""
    la, lb = pointwise(fit_a), pointwise(fit_b)
    if la is None or lb is None or la.shape != lb.shape or la.size < 10:
        return None
    d = la - lb
    n = d.size
    lags = nw_lags(n)
    lr = float(d.sum()) - (fit_a.stats.k_lik - fit_b.stats.k_lik)
    s2 = long_run_variance(d, lags)
    if not s2 > 0:
        return VuongResult(fit_a.law, fit_b.law, 0.0, 1.0, n, lags, lr)
    from scipy.special import ndtr

    z = lr / math.sqrt(n * s2)
    return VuongResult(fit_a.law, fit_b.law, z, float(2 * ndtr(-abs(z))), n, lags, lr)


def closer_sentence(fit_a, fit_b) -> tuple[str, str, dict]:
    """(sentence, a few words, numbers) comparing two fits of one dataset on one likelihood: Vuong's test beside
    the differences of -2 ln L, AIC and BIC (B minus A) and the two Akaike weights, and whether they all order
    the laws the same way; ('', '', {}) where the test cannot be made."""
    r = vuong(fit_a, fit_b)
    if r is None:
        return "", "", {}
    sa, sb = fit_a.stats, fit_b.stats
    d_ll, d_aic, d_bic = sb.neg2loglik - sa.neg2loglik, sb.aic - sa.aic, sb.bic - sa.bic
    w_a = 1.0 / (1.0 + math.exp(-0.5 * max(min(d_aic, 1400.0), -1400.0)))
    signs = {math.copysign(1, v) for v in (d_ll, d_aic, d_bic, r.z) if v != 0}
    agree = "every measure orders them alike" if len(signs) <= 1 else "the measures do not order them alike"
    numbers = {"z": r.z, "p": r.p, "lags": r.lags, "d_neg2loglik": d_ll, "d_aic": d_aic, "d_bic": d_bic,
               "weight_a": w_a, "law_a": fit_a.law, "law_b": fit_b.law, "closer": r.closer}
    text = (f"{fit_a.law} against {fit_b.law} on one likelihood (each law's own noise model): {r.text}; "
            f"-2 ln L, AIC and BIC of {fit_b.law} minus {fit_a.law}: {d_ll:+.3g}, {d_aic:+.3g}, {d_bic:+.3g}; "
            f"Akaike weights {w_a:.3g} and {1 - w_a:.3g}; {agree}")
    p = f"{r.p:.2g}" if r.p >= 1e-3 else f"{r.p:.0e}"
    short = f"{r.closer} closer (Vuong p = {p})" if r.closer else f"equally close at this noise (Vuong p = {p})"
    return text, short, numbers
