"""Every rule the verdicts apply, in words, each threshold read from the constant of the module that applies it.

The report quotes these sentences and nothing else for its rules, so a threshold printed is the threshold
applied (``tests/test_rules.py`` reads them back from a rendered report and checks each against its constant).
"""
from __future__ import annotations

from ..equivalence import discrimination as eq
from ..diagnostics import goodness as gd
from ..diagnostics import identifiability as ident
from ..diagnostics import plausibility as pl
from . import ranking as rk
from ..equivalence.margin import MARGIN


def goodness() -> str:
    """The goodness-of-fit rule."""
    return (f"a candidate fits when each of its two tests has p ≥ {gd.TEST_LEVEL:g}: the χ² test (an F test with "
            "the estimate's degrees of freedom where σ is estimated) and the one-sided Wald-Wolfowitz runs test on "
            f"its residual signs, one family-wise level of {gd.FITS_LEVEL:g} (Bonferroni over the two tests, and "
            "over the members of a group); the top candidate is called best only if it fits and carries no "
            "plausibility flag")


def ties() -> str:
    """Shared ranks and near-ties."""
    return (f"candidates within ΔAIC ≤ {rk.TIE_AIC:g} share a rank (the same curve); within ΔAIC < {rk.NEAR_TIE:g} "
            "they are indistinguishable by these data")


def weights() -> str:
    """What an Akaike weight compares."""
    return ("an Akaike weight w = exp(−Δ/2) / Σ exp(−Δ/2) compares the candidates of one dataset that pass their "
            "fit tests, and is given with them; a candidate that fails gets none, and where only one fits its "
            "weight is 1 by construction")


def plausibility() -> str:
    """The plausibility flags."""
    return (f"a fit is flagged when its slip or r|ω| exceeds {pl.RANGE:g}× the starting speed, when friction does "
            f"net negative work beyond {pl.WORK_TOL:.0%} of its total work, or when a fitted law parameter set to 0 "
            f"changes χ² by no more than round-off ({pl.NIL_REL:g} of max(χ², n)); a flagged fit ranks after the "
            "unflagged ones that fit")


def bounds() -> str:
    """When a parameter is at a bound, and what that means."""
    return (f"a parameter within {ident.AT_BOUND_REL:.0%} of a nonzero bound (or {ident.AT_BOUND:g} of its typical "
            f"size of a zero bound) is at that bound: {ident.AT_BOUND_MEANING}")


def correlation() -> str:
    return (f"parameters correlated beyond |r| > {ident.CORRELATION_LIMIT:g} are named: the data determine a "
            "combination of them better than either")


def equivalence(replicates: int, margin_text: str, family_text: str) -> str:
    """The three answers of the equivalence test, the no-test case and the error rate."""
    return (
        "Each pair of laws is tested on each dataset, and gets one of three answers. "
        f"**{eq.DIFFERENT}**: a Cox-type discrimination test rejects one law against the other. Its statistic is "
        "T = χ²(A) − χ²(B) at the σ the likelihood uses (measured, estimated from the data, or a reconstruction's "
        "stated precision; −2 ln of the likelihood ratio), each law tested with T centred at its location under "
        "that law's fit (the other law refitted to its best curve: Cox's statistic); replicate datasets are "
        "simulated from each law's best fit with that σ (an estimated σ re-drawn per replicate from its "
        "chi-square law), both laws refitted to each and T re-centred, sequentially in batches of "
        f"{eq.BATCH} (at most {replicates} per law); the two-sided p = 2 min(p_A, p_B) must fall below "
        f"α = {eq.ALPHA:g} after the family's adjustment. **{eq.WITHIN}**: the upper {1 - eq.ALPHA:.0%} bound of "
        "the RMS distance between the two best curves (in the observable's unit; its error from the same "
        "replicates, in the sense of Schuirmann's two one-sided tests) lies below the margin δ, and no law is "
        f"rejected; δ is {margin_text}. **{eq.CANNOT}**: neither. **{eq.BOTH_FAIL}**: where both laws fail their "
        "own fit tests, neither is a valid null for the other: the pair gets no p-value, and only the two misfits "
        f"are compared. Error rate: {family_text}. The noise threshold, both directions: the σ at which a fit of "
        f"one law to the other's noise-free best curve misses it by χ² {eq.CRITICAL:g} (about 50% power).")


def margin_default() -> str:
    return (f"{MARGIN:g} × the noise σ of each dataset (stated precisions for a reconstruction's stated numbers), "
            "the default; change it with --margin")


def qualitative() -> str:
    return ("'qualitatively' (the word of Arakawa 2017): do the two fitted curves share the data's features (a rise, a "
            "peak inside the record, a fall before the end, one sign of the friction force)? Peak times are "
            "compared apart, as a quantitative difference: they differ when more than the sampling interval apart")
