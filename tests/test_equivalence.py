"""The equivalence analysis: decomposition numbers, cross-fits, verdicts that respond to the data."""
import math

import numpy as np
import pytest

from _fit_helpers import TC, TRUTH, impact_scene, incline_scene, synthetic
from frictionlab import analyze_equivalence, fit
from frictionlab.equivalence import decomposition


def test_decomposition_matches_the_closed_form_on_the_half_sine_scene():
    ds = synthetic("wear", {"lam": 1.2e6})
    fw = fit("wear", ds, solver="series")
    d = decomposition(fw)
    s = impact_scene()
    lam, A0, u0, m = fw.value("lam"), s.area.peak, s.u0, s.mass
    phi = math.pi / TC
    b = lam * A0 / (m * phi)
    N0 = s.normal.peak
    assert d.b == pytest.approx(b)
    assert d.c_area == pytest.approx(lam * u0 * (1 - b))
    assert d.c_area_rate == pytest.approx(lam * u0 * b / (phi * A0))  # 1/(phi A0), not the printed phi/A0
    # same contact time for A and N: mu = c1 A0 / N0 and mu eta' = c2 * 4 A0 / (3 pi)
    assert d.mu == pytest.approx(d.c_area * A0 / N0, rel=1e-3)
    assert d.mu * d.eta_prime == pytest.approx(d.c_area_rate * 4 * A0 / (3 * math.pi), rel=1e-3)
    assert 0.0 < d.r2 < 1.0  # A dA/dt is not a multiple of dA/dt: the forms differ


def test_series_wear_and_area_rate_are_similar_but_exact_wear_is_not():
    """On data from the area-rate law (spin rises then falls), the truncated wear series follows the
    same shape while the exact wear solution cannot fall: the verdicts must differ accordingly."""
    ds = synthetic("area-rate", TRUTH["area-rate"], seed=3)
    fa = fit("area-rate", ds, solver="exact")
    exact = analyze_equivalence(fit("wear", ds, solver="exact"), fa)
    series = analyze_equivalence(fit("wear", ds, solver="series"), fa)
    assert exact.status == series.status == "ok"
    assert exact.verdict == "not equivalent"
    assert exact.checks["same curve shape"] is False
    assert "rises throughout" in exact.shape["wear"] and "falls" in exact.shape["area-rate"]
    assert series.checks["same curve shape"] is True
    assert series.force_correlation > exact.force_correlation
    for e in (exact, series):
        assert {c.law for c in e.cross} == {"wear", "area-rate"}
        assert all(c.status == "ok" and c.dchi2 > 2.0 for c in e.cross)  # 1% noise tells them apart
        assert all(c.dchi2 == pytest.approx(26 * c.rms_sigma**2) for c in e.cross)
        assert e.decomposition is not None
        assert str(round(e.force_correlation, 3)) in e.explanation


def test_verdict_follows_the_noise_level():
    """The same two laws are 'equivalent at this noise' when the data are poor, not when they are good."""
    scene = incline_scene()
    noisy = synthetic("couette", TRUTH["couette"] | {"h": 4e-5}, scene, n=30, rel_noise=2.0, seed=5)
    clean = synthetic("couette", TRUTH["couette"] | {"h": 4e-5}, scene, n=30, rel_noise=0.002, seed=5)
    verdicts = {}
    for name, ds in (("noisy", noisy), ("clean", clean)):
        e = analyze_equivalence(fit("wear", ds, solver="exact"), fit("area-rate", ds, solver="exact"))
        verdicts[name] = e
        assert e.decomposition is None  # no half-sine area on an incline
    assert verdicts["noisy"].verdict == "equivalent at this noise"
    assert verdicts["clean"].verdict == "not equivalent"
    assert all(c.dchi2 > 2 for c in verdicts["clean"].cross)
    assert all(c.dchi2 <= 2 for c in verdicts["noisy"].cross)


def test_failed_or_skipped_fit_skips_the_analysis():
    ds = synthetic("wear", {"lam": 1.2e6}, incline_scene(), n=20)
    fw = fit("wear", ds, solver="series")  # no series on an incline: skipped
    fa = fit("area-rate", ds, solver="exact")
    e = analyze_equivalence(fw, fa)
    assert e.status == "skipped" and "series" in e.reason and e.verdict == ""


def test_force_history_numbers():
    ds = synthetic("wear", {"lam": 1.2e6})
    fw = fit("wear", ds, solver="exact")
    e = analyze_equivalence(fw, fit("area-rate", ds, solver="exact"), cross=False)
    assert -1.0 <= e.force_correlation <= 1.0 and e.force_distance >= 0
    t = np.linspace(0, TC, 801)
    Fw = fw.per_dataset[0].trajectory(fw.law, t).force
    assert e.impulse["wear"] == pytest.approx(np.trapezoid(Fw, t), rel=1e-9)
    # the spin the wear fit reaches equals r/I times its impulse
    s = impact_scene()
    assert fw.per_dataset[0].model[-1] == pytest.approx(s.radius * e.impulse["wear"] / s.inertia, rel=1e-3)
