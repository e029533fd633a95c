"""The GCV smoothing spline of theta(t) in closed form against scipy's make_smoothing_spline."""
import numpy as np
import pytest
from scipy.interpolate import make_smoothing_spline

from frictionlab.core.errors import DatasetError
from frictionlab.io.dataset import load_dataset
from frictionlab.physics.derive import _gcv_spline, _spline_operators, derive_omega
from frictionlab.report.derivation import derivations

GOLF = ("impact-golf-v28", "impact-golf-v61")


def grid(t):
    """The penalties _spline_operators chooses among [s^3]."""
    return (t[-1] - t[0]) ** 3 * np.logspace(-14, 1, 61)


def scipy_operators(t, lam):
    """S and D of make_smoothing_spline at penalty lam, by fitting the identity."""
    spl = make_smoothing_spline(t, np.eye(t.size), lam=lam)
    return spl(t), spl.derivative()(t)


def scipy_gcv(t, theta):
    """GCV on the grid with scipy's smoother (the plain route), per penalty."""
    n = t.size
    out = []
    for lam in grid(t):
        S, _ = scipy_operators(t, lam)
        out.append(n * np.sum((theta - S @ theta) ** 2) / max(n - np.trace(S), 1e-9) ** 2)
    return np.array(out)


def close(a, b, rtol):
    return np.max(np.abs(a - b)) <= rtol * np.max(np.abs(b))


def random_times(seed, n, start):
    return start + np.cumsum(np.random.default_rng(seed).uniform(0.2, 1.0, n)) * 1e-3


TIMES = [load_dataset(name).t for name in GOLF] + [random_times(s, n, t0) for s, (n, t0) in
                                                   enumerate([(5, 0.0), (12, 2.0), (40, 0.0), (80, 0.5)])]


@pytest.mark.parametrize("t", TIMES, ids=lambda t: f"n{t.size}")
def test_smoother_and_derivative_equal_scipys_at_fixed_penalties(t):
    theta = np.random.default_rng(t.size).normal(size=t.size)
    for scale in (1e-14, 1e-8, 1e-4, 1e-1, 10.0):
        lam = (t[-1] - t[0]) ** 3 * scale
        chosen, S, D = _gcv_spline(t, theta, np.array([lam]))
        S_ref, D_ref = scipy_operators(t, lam)
        # at the grid's stiffest end scipy's banded solve itself loses digits (condition ~ lam |K|)
        rtol = 1e-9 if scale < 1 else 3e-8
        assert chosen == lam and close(S, S_ref, rtol) and close(D, D_ref, rtol), scale
        line = 3.0 - 2.0 * (t - t[0])
        assert np.allclose(S @ line, line, rtol=0, atol=1e-11) and np.allclose(D @ line, -2.0, rtol=1e-9)


def golf_thetas():
    """Each dataset's theta as given, as derivations() perturbs it, and with seeded noise of 0.1 to 10 mrad."""
    for name in GOLF:
        ds = load_dataset(name)
        theta = ds.columns["theta"]
        yield name, "given", ds.t, theta, None
        yield name, "derivations", ds.t, derivations(ds)[1]["_theta"], None
        for sigma in (1e-4, 1e-3, 1e-2):
            yield name, f"noise {sigma}", ds.t, theta + np.random.default_rng(0).normal(0, sigma, theta.size), sigma


@pytest.mark.parametrize("name,case,t,theta,sigma", list(golf_thetas()), ids=lambda v: v if isinstance(v, str) else "")
def test_gcv_choice_matches_the_grid_search_with_scipy(name, case, t, theta, sigma):
    chosen, S, D = _gcv_spline(t, theta, grid(t))
    k = int(np.flatnonzero(grid(t) == chosen)[0])
    old = scipy_gcv(t, theta)
    # the grid penalties whose GCV scipy's smoother cannot tell from its minimum: on the noiseless columns
    # GCV rises with lam by parts in 1e8 at the grid's low end, below the round-off of theta - S theta there
    ties = np.flatnonzero(old <= old.min() * (1 + 1e-4))
    assert k in ties
    if sigma is not None:  # noisy theta: a clear interior minimum, the same penalty
        assert list(ties) == [k] and 0 < k < 60
    S_ref, D_ref = scipy_operators(t, chosen)
    assert close(S, S_ref, 1e-9) and close(D, D_ref, 1e-9)
    S_old, D_old = scipy_operators(t, grid(t)[int(np.argmin(old))])
    assert close(S, S_old, 1e-7) and close(D, D_old, 1e-7)
    assert np.array_equal(_spline_operators(t, theta)[1], D)


def test_spline_needs_five_increasing_times():
    t = np.linspace(0.0, 1e-3, 8)
    with pytest.raises(DatasetError, match="at least 5"):
        derive_omega(t[:4], t[:4], "spline")
    with pytest.raises(DatasetError, match="strictly increasing"):
        derive_omega(t[::-1], t, "spline")
