"""How the velocity-step fit's optimizer sees its parameters (inference.velstep.params): Nagata's b through a
softplus, its derivatives, its bounds, and the fit's refits that let b go below 0."""
from __future__ import annotations

import sys
from pathlib import Path

import attrs
import numpy as np
import pytest

import frictionlab as fl
from frictionlab.inference.fitting.predict import Target
from frictionlab.inference.velstep import fit as velstep
from frictionlab.inference.velstep.params import AB_SCALE, B_KNEE, Param
from frictionlab.solve import quasistatic

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))


def softplus_b(lower=1e-5, upper=0.5):
    return Param("b", "b", -1, "softplus", 0.01, lower, upper, True, scale=B_KNEE)


def test_a_softplus_parameter_is_logarithmic_below_its_knee_and_linear_above():
    p = softplus_b()
    for v in (2e-5, 3e-4, B_KNEE, 0.01, 0.2, 0.4):
        assert p.from_x(p.to_x(v)) == pytest.approx(v, rel=1e-12) and p.to_x(v) < p.to_x(v * 1.001)
        h = 1e-6 * max(1.0, abs(p.to_x(v)))
        fd = (p.from_x(p.to_x(v) + h) - p.from_x(p.to_x(v) - h)) / (2 * h)
        assert p.slope_at(v) == pytest.approx(fd, rel=1e-6) and p.slope(p.to_x(v)) == pytest.approx(fd, rel=1e-6)
    assert p.slope_at(1e-5) == pytest.approx(1e-5, rel=1e-2)  # d b / d x = b: x is ln b there
    assert p.slope_at(0.5) == pytest.approx(B_KNEE, rel=1e-12)  # x is b / B_KNEE there
    lo, hi = p.bounds_x
    assert p.from_x(lo) >= 1e-5 and p.from_x(lo - 1.0) == 1e-5 and p.from_x(hi + 1.0) == 0.5  # never outside


def test_nagatas_b_is_seen_through_a_softplus_and_the_other_laws_b_linearly(tmp_path):
    from calibration_ar1 import make_dataset

    ds, curve = make_dataset(tmp_path, "none", True)
    data = attrs.evolve(ds, columns=dict(ds.columns, mu=curve), noise={"mu": 4e-4})
    tg = [Target(data, "mu", curve, np.full(curve.size, 4e-4))]
    seen = {law: next(p for p in velstep.make_problem(fl.get_law(law), tg, {}, {}, {}, None, None, 1e-8).params
                      if p.key == "b") for law in ("rate-state-aging", "rate-state-nagata")}
    assert (seen["rate-state-aging"].transform, seen["rate-state-aging"].scale) == ("lin", AB_SCALE)
    assert (seen["rate-state-nagata"].transform, seen["rate-state-nagata"].scale) == ("softplus", B_KNEE)


def test_the_gradient_through_a_softplus_b_is_that_of_chi_square(tmp_path):
    """J'r of Nagata's fit (the sensitivities combined through d b / d x) against central differences of
    chi-square in the optimizer's variables, at a small b, where x is about ln b."""
    from calibration_ar1 import make_dataset

    ds, _ = make_dataset(tmp_path, "none", True)
    load = quasistatic.Load.of(ds.scene.spring)
    code = quasistatic.LAWS["rate-state-nagata"]
    y = 0.6 + quasistatic.solve(code, 0.012, 2e-4, 10.0, 0.008, load, ds.t, 1e-10, c=0.5).m
    y = y + np.random.default_rng(8).normal(0.0, 2e-4, y.size)
    data = attrs.evolve(ds, columns=dict(ds.columns, mu=y), noise={"mu": 2e-4})
    pb = velstep.make_problem(fl.get_law("rate-state-nagata"), [Target(data, "mu", y, np.full(y.size, 2e-4))], {}, {},
                              {"a": 0.011, "b": 3e-4, "Dc": 8e-6, "c": 0.4}, None, None, 1e-10)
    x = pb.x_start()
    cost, g, _, ok = pb.evaluate(x, pb.free)
    assert ok
    for j, i in enumerate(pb.free):
        h = 1e-6 * max(1.0, abs(x[i]))
        up, dn = x.copy(), x.copy()
        up[i] += h
        dn[i] -= h
        fd = (pb.evaluate(up, pb.free)[0] - pb.evaluate(dn, pb.free)[0]) / (2 * h)
        assert 2 * g[j] == pytest.approx(fd, rel=1e-4, abs=1e-6 * abs(cost)), pb.params[i].name


def test_nagatas_b_at_its_bound_is_refitted_below_0_as_the_aging_law_is(tmp_path):
    """Nagata's law with c held at 0 is the aging law: on a strengthening evolution (b = -0.004) its b ends at its
    lower bound, and the diagnostic refit, which sees b linearly to let it go below 0, finds b = -0.004."""
    from calibration_ar1 import make_dataset

    ds, _ = make_dataset(tmp_path, "none", True)
    load = quasistatic.Load.of(ds.scene.spring)
    y = 0.6 + quasistatic.solve(0, 0.01, -0.004, 10.0, 0.008, load, ds.t, 1e-10).m
    y = y + np.random.default_rng(3).normal(0.0, 2e-4, y.size)
    data = attrs.evolve(ds, columns=dict(ds.columns, mu=y), noise={"mu": 2e-4})
    f = fl.fit("rate-state-nagata", Target(data, "mu", y, np.full(y.size, 2e-4)), fixed={"c": 0.0})
    assert f.ok and f.value("b") == 1e-5 and "b" in f.identifiability.at_bounds
    found = [m for m in f.velstep.missing if "strengthening" in m]
    assert found and "b = -0.004" in found[0]
