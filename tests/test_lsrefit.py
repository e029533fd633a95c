"""Replicate refits through scipy's public least squares (``inference.fitting.lsrefit``) against lmfit's own
Levenberg-Marquardt run: the same minimum to stated tolerances, and a clear refusal where it cannot answer."""
import math

import pytest
from _fit_helpers import TRUTH, synthetic

from frictionlab import fit


@pytest.mark.parametrize("law, options", [
    ("area-rate", {"scan": 0, "n_starts": 1}),  # a bootstrap replicate: warm start, error analysis
    ("wear", {"scan": 0, "n_starts": 1, "errors": False}),  # an equivalence replicate
    ("couette", {"scan": 25, "n_starts": 2, "errors": False}),  # cross_chi2: two starts, eta and h held apart
    ("area-rate", {"free": {"u0": (5.0, 30.0)}}),  # a scene quantity fitted beside the law's
    ("coulomb", {"fixed": {"mu": 0.2}, "free": {"u0": (5.0, 30.0)}}),  # a held law parameter
    ("wear", {"initial": {"lam": 5e8}, "scan": 0, "n_starts": 1}),  # a start far away: the fit walks
])
def test_refits_through_least_squares_reach_lmfits_minimum(law, options, monkeypatch):
    """fit(checks=False) refits through scipy's least_squares (lsrefit.leastsq): its chi-square is lmfit's
    Levenberg-Marquardt minimum to 1e-7 of it (or lower), its values within 1e-3 of their error bars, its error
    bars within 1e-3 of lmfit's."""
    from frictionlab.inference.fitting import batch as batchfit, lsrefit

    monkeypatch.setattr(batchfit, "best_start", lambda *a: None)  # the batched starts aside (tests/test_batchfit.py)
    data = synthetic(law, TRUTH[law], n=21, name=f"direct-{law}", rel_noise=0.03)
    calls = []
    direct_run = lsrefit.leastsq
    monkeypatch.setattr(lsrefit, "leastsq", lambda *a, **k: calls.append(1) or direct_run(*a, **k))
    direct = fit(law, data, solver="exact", checks=False, **options)
    monkeypatch.setattr(lsrefit, "leastsq", lambda *a, **k: None)  # declined: lmfit runs
    general = fit(law, data, solver="exact", checks=False, **options)
    assert calls and direct.ok and general.ok
    assert direct.stats.chisqr <= general.stats.chisqr * (1 + 1e-7)
    for k, p in general.params.items():
        q = direct.params[k]
        if p.stderr:
            assert abs(q.value - p.value) <= 1e-3 * p.stderr, k
            if options.get("errors", True):
                assert q.stderr == pytest.approx(p.stderr, rel=1e-3), k
        elif p.vary:  # lmfit could not estimate its error bar: the data do not determine it; nor does the refit
            assert not q.stderr, k
        else:
            assert q.value == p.value, k


def test_a_refit_through_least_squares_declines_where_it_cannot_answer():
    """A residual that is not finite, or the evaluation budget reached: None, so that lmfit runs (and says
    what it says there); an error bar that cannot be estimated (a flat residual) is said, as lmfit says it."""
    import numpy as np

    from frictionlab.inference.fitting import lsrefit

    params = {"a": lsrefit.Param("a", 1.0, 0.0, 10.0, True)}
    assert lsrefit.leastsq(lambda v: np.array([np.nan, 1.0]), params, True, 50) is None
    assert lsrefit.leastsq(lambda v: np.array([v["a"] - 3.0, 1e-3 * math.sin(50 * v["a"])]), params, True, 1,
                           ftol=1e-15, xtol=1e-15) is None
    flat = lsrefit.leastsq(lambda v: np.array([1.0, 2.0]), params, True, 50)
    assert flat.success and flat.params["a"].stderr is None and "Could not estimate error-bars" in flat.message
    line = lsrefit.leastsq(lambda v: np.array([v["a"] - 3.0, v["a"] - 5.0]), params, False, 50)
    assert line.params["a"].value == pytest.approx(4.0, rel=1e-8) and line.chisqr == pytest.approx(2.0)
    assert line.params["a"].stderr == pytest.approx(math.sqrt(0.5), rel=1e-6)  # (J^T J)^-1 = 1/2
