"""The clear-rejection shortcut of the sequential equivalence test (``equivalence._far`` / ``_p_side``): from
FAR_MIN replicates on, an observed statistic beyond every replicate whose exponential-tail p is below FAR_P
stops the sampling and reports that tail p (floored at TAIL_FLOOR). It must fire only far out, never where
p is near alpha, and its p must be conservative against a long plain Monte-Carlo run."""
import math

import numpy as np
import pytest

from frictionlab.inference.equivalence import discrimination as eq


def _null(rng, m=eq.FAR_MIN):
    return rng.standard_normal(m)


def test_it_fires_far_beyond_every_replicate_and_reports_the_tail_p():
    rng = np.random.default_rng(0)
    sample, middle = _null(rng), _null(rng)
    x = sample.max() + 8.0  # eight standard deviations beyond the largest replicate
    assert eq._far(sample, x)
    p = eq._p_side(sample, x, 0.0)
    assert eq.TAIL_FLOOR <= p < eq.FAR_P < 1 / (sample.size + 1)  # below the Monte-Carlo floor 1/41
    assert p == max(eq._tail(sample, x), eq.TAIL_FLOOR)
    assert "tail-estimated" in eq._clear(sample, x, middle, 0.0, 0.0)
    assert eq._p_side(sample, x + 1e3, 0.0) == eq.TAIL_FLOOR  # extrapolation is floored, never 0


def test_it_does_not_fire_where_p_is_near_alpha():
    """Just beyond the largest of 40 replicates the p-value is about 1/41 = 0.024, at alpha / 2: the shortcut
    must not stop sampling there (nor with fewer than FAR_MIN replicates however far out)."""
    rng = np.random.default_rng(1)
    sample, middle = _null(rng), _null(rng)
    x = sample.max() + 0.05
    assert eq._tail(sample, x) > eq.FAR_P and not eq._far(sample, x)
    assert eq._p_side(sample, x, 0.0) == pytest.approx(1 / (sample.size + 1))  # the plain Monte-Carlo p
    assert eq._clear(sample, x, middle, 0.0, 0.0) == ""  # undecided: sampling goes on
    few = sample[: eq.FAR_MIN - 1]
    assert not eq._far(few, few.max() + 50.0)


@pytest.mark.parametrize("family", ["normal", "chi2_1", "chi2_3", "gumbel"])
def test_its_p_is_conservative_against_a_long_plain_monte_carlo_run(family):
    """Observed statistic and 40 replicates drawn from one null, 20,000 times: the reported p must satisfy
    P(p <= v) <= v at v = FAR_P and 1e-3 (a valid p-value), with Monte-Carlo slack. With the plain mean
    excess as the tail's scale (the previous rule) chi-square and Gumbel nulls gave 2-5 times v."""
    rng = np.random.default_rng(2)
    draw = {"normal": lambda s: rng.standard_normal(s), "chi2_1": lambda s: rng.chisquare(1, s),
            "chi2_3": lambda s: rng.chisquare(3, s), "gumbel": lambda s: rng.gumbel(size=s)}[family]
    n = 20_000
    samples, xs = draw((n, eq.FAR_MIN)), draw(n)
    beyond = np.flatnonzero(xs > samples.max(axis=1))
    ps = np.array([eq._p_side(samples[i], xs[i], 0.0) for i in beyond])
    for v in (eq.FAR_P, 1e-3):
        k, expect = int(np.sum(ps <= v)), n * v
        assert k <= expect + 3 * math.sqrt(expect), (family, v, k, expect)


def test_a_real_clear_rejection_stops_early_and_agrees_with_the_plain_run(monkeypatch):
    """Coulomb data at 1% noise, Coulomb against wear: the shortcut stops at FAR_MIN replicates with a tail p
    for wear; the plain run (shortcut off, 200 replicates) has no replicate beyond the data either, so its p
    is its floor 1/201, and the verdicts agree."""
    from _fit_helpers import TRUTH, synthetic

    from frictionlab import analyze_equivalence, fit

    ds = synthetic("coulomb", TRUTH["coulomb"], seed=3)
    fc, fw = fit("coulomb", ds), fit("wear", ds)
    fast = analyze_equivalence(fc, fw, replicates=200)
    m = eq.FAR_MIN
    assert "tail-estimated" in fast.stopped and fast.s_b.size == m, fast.stopped
    monkeypatch.setattr(eq, "FAR_MIN", 10**9)
    monkeypatch.setattr(eq, "CI_LEVEL", 1 - 1e-12)  # no early stop at all: the plain Monte-Carlo run
    plain = analyze_equivalence(fc, fw, replicates=200)
    assert plain.s_b.size == 200 and plain.p_b == pytest.approx(1 / 201)
    np.testing.assert_array_equal(plain.s_b[:m], fast.s_b)  # the same first draws
    assert fast.verdict == plain.verdict == "different" and fast.p_b < plain.p_b
