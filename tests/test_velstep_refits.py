"""The refits inside a comparison of velocity steps (the equivalence test's cross-fit, its centrings and its
replicates) use the velocity-step fit's own model: trend, stiffness, step time and noise. Each is run through the
comparison's path and compared with a direct velocity-step fit."""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import frictionlab as fl
from frictionlab.inference.resampling import replicates as rp
from frictionlab.inference.noise import arp

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

AGING, SLIP = "rate-state-aging", "rate-state-slip"


@pytest.fixture(scope="module")
def pair(tmp_path_factory):
    from calibration_vuong import data_of, make_dataset, truth

    ds, x, v1 = make_dataset(tmp_path_factory.mktemp("refits"), 3.0)
    curve = truth(ds, x, v1, AGING)
    noise = arp.draw(np.random.default_rng(11), arp.from_coefficients((0.6, -0.2)), curve.size, 3e-4)
    target = data_of(ds, curve + noise)
    fa = fl.fit(AGING, target, trend=True, stiffness=True)
    fb = fl.fit(SLIP, target, trend=True, stiffness=True)
    return target, fa, fb


def test_refit_options_carry_the_fit_s_trend_stiffness_and_noise(pair):
    _, fa, _ = pair
    opts = rp.refit_options(fa)
    assert opts["trend"] is True and opts["stiffness"] is True and "spring.stiffness" in opts["free"]
    (state,) = rp.noise_of(fa)
    assert state["kind"] == "arp" and [m.name for m in state["models"]] == ["AR(2)"]


def test_the_cross_fit_is_a_velocity_step_fit_at_the_curve_s_noise(pair):
    target, fa, fb = pair
    chi = rp.cross_chi2(fb, fa)  # slip refitted to aging's noise-free best curve
    direct = fl.fit(SLIP, rp.with_y(target, fa.per_dataset[0].model.copy(), "curve"), trend=True, stiffness=True,
                    noise=rp.noise_of(fa), scan=25, n_starts=2)
    assert "velocity-step fit" in direct.message
    assert chi == pytest.approx(direct.stats.chisqr, rel=1e-3)
    # the misfit of one law's curve by the other in units of the data's noise, not a profiled level
    assert 1.0 < chi < 0.1 * target.y.size


def test_a_centring_refit_reproduces_the_fit_s_own_curve(pair):
    target, fa, _ = pair
    d = fa.per_dataset[0]
    chi, model = rp.centring_fit(AGING, rp.refit_options(fa), fa, target, d.model, rp.noise_of(fa))
    assert chi < 1e-3  # the law, its trend, stiffness and step time reach their own curve
    assert np.max(np.abs(model - d.model)) < 1e-3 * 3e-4


def test_a_replicate_refit_is_the_direct_fit_of_the_replicate(pair):
    target, fa, fb = pair
    y = fa.per_dataset[0].model + arp.draw(np.random.default_rng(12), arp.from_coefficients((0.6, -0.2)),
                                           target.y.size, 3e-4)
    tg = rp.with_y(target, y, "replicate")
    ra = rp.refit(AGING, rp.refit_options(fa), tg)
    direct = fl.fit(AGING, tg, trend=True, stiffness=True)
    assert "velocity-step fit" in ra.message and ra.per_dataset[0].noise_state["kind"] == "arp"
    assert ra.stats.neg2loglik == pytest.approx(direct.stats.neg2loglik, abs=0.05)
    for name in ("a", "b", "Dc", "spring.stiffness"):
        assert abs(ra.value(name) - direct.value(name)) < 0.05 * direct.params[name].stderr, name
    t, s, dist = rp._null_row(((AGING, rp.refit_options(fa)), (SLIP, rp.refit_options(fb))), target, "a", y)
    rb = rp.refit(SLIP, rp.refit_options(fb), tg)
    assert t == pytest.approx(rp.t_stat(ra, rb), abs=1e-9) and np.isfinite(s) and dist > 0
