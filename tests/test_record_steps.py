"""One parameter set across a record's steps (known truth: one set must be accepted, two sets refused) and the
first screen that answers it; the registered state laws the test takes."""
from __future__ import annotations

import numpy as np
import pytest

import frictionlab as fl
from frictionlab.inference.velstep.record_steps import answer, ar1_neg2ll, fit_steps, state_laws
from frictionlab.io.dataset import Dataset
from frictionlab.io.provenance import Provenance
from frictionlab.physics.scene import ConstantNormal, Scene, SpringLoad
from frictionlab.report.record_screen import screen

TRUTH = {"mu0": 0.6, "a": 0.008, "b": 0.012, "Dc": 10e-6}
K, SIGMA, DT = 1e4, 2e-4, 0.2


def _step(name, v1, v2, params, seed, law="rate-state-aging"):
    """A step window from steady sliding at v1 [m/s] to v2 at 20 s, 80 s long, known white noise."""
    scene = Scene(kind="spring-slider", mass=1.0, u0=v1, duration=100.0, normal=ConstantNormal(1e4),
                  spring=SpringLoad(K, (0.0, 20.0), (v1, v2)))
    t = np.arange(0.0, 100.0, DT)
    mu = fl.simulate(law, scene, params, t=t).load + np.random.default_rng(seed).normal(0, SIGMA, t.size)
    return Dataset(name=name, kind="spring-slider", observable="mu", path=None, columns={"t": t, "mu": mu},
                   units={"t": "s", "mu": ""}, noise={"mu": SIGMA}, scene=scene, fixed={}, noise_kind="known",
                   provenance=Provenance(kind="synthetic", source="tests", seed=seed))


def test_the_state_laws_are_the_registered_ones_the_fit_serves():
    laws = state_laws()
    assert {"rate-state-aging", "rate-state-slip"} <= set(laws) and "coulomb" not in laws
    assert all(name in fl.available_laws() for name in laws)
    assert set(state_laws(fitted_only=True)) <= set(laws)


def test_one_set_is_accepted_on_one_law_and_refused_on_two(tmp_path):
    same = [_step("s-up", 1e-6, 1e-5, TRUTH, 1), _step("s-down", 1e-5, 1e-6, TRUTH, 2)]
    r = fit_steps("rate-state-aging", same)
    assert r.ok and r.one_set, r.verdict()
    assert r.shared.dk == 3 and r.shared.shared["b"] == pytest.approx(TRUTH["b"], rel=0.1)
    other = dict(TRUTH, b=0.016, Dc=30e-6)
    two = [_step("t-up", 1e-6, 1e-5, TRUTH, 3), _step("t-down", 1e-5, 1e-6, other, 4)]
    r2 = fit_steps("rate-state-aging", two)
    assert r2.ok and r2.one_set is False and r2.shared.p_value < 1e-6, r2.verdict()
    text = answer([r, r2], ["up", "down"])
    assert text.startswith("Does one parameter set describe the up and the down steps?")
    steps = [dict(name=d.name, label="1 -> 10", direction="up", window="500 samples", note="starts at steady state")
             for d in same]
    lines = screen("title", steps, [r], answer([r], ["up", "down"]))
    assert "Yes, for every law tested (aging)" in lines[2] and any("one set of a, b, Dc" in x for x in lines)


def test_nagata_shares_c_with_a_b_dc_across_the_steps_and_the_screen_shows_it():
    """Nagata data (c = 2) stepped up and down with one parameter set: the velocity-step fit serves each step, the
    shared set includes c (4 shared parameters, one per step beyond the first), one set is accepted, and the
    first screen has a column for c in the per-step and the shared tables."""
    assert "rate-state-nagata" in state_laws(fitted_only=True)
    truth = dict(TRUTH, c=2.0)
    same = [_step("n-up", 1e-6, 1e-5, truth, 5, "rate-state-nagata"),
            _step("n-down", 1e-5, 1e-6, truth, 6, "rate-state-nagata")]
    r = fit_steps("rate-state-nagata", same)
    assert all(f.solver == "ode" and f.velstep is not None for f in r.steps)
    assert r.ok and r.one_set and r.shared.dk == 4, r.verdict()
    assert abs(r.shared.shared["c"] - 2.0) < 3 * max(f.stderr("c") for f in r.steps)
    steps = [dict(name=d.name, label="1 -> 10", direction="up", window="500 samples", note="starts at steady state")
             for d in same]
    lines = screen("title", steps, [r], answer([r], ["up", "down"]))
    assert any("one set of a, b, Dc, c describes every step" in x for x in lines)
    assert any(x.startswith("One set for every step (a, b, Dc, c shared") for x in lines)
    header = next(x for x in lines if x.lstrip().startswith("step "))
    assert "Dc [um]  c " in header or " c  " in header


def test_the_ar1_likelihood_profiles_phi_and_the_variance():
    class D:  # a fit's dataset part: only its residuals are read
        def __init__(self, r):
            self.residual = r

    class F:
        def __init__(self, *rs):
            self.per_dataset = [D(r) for r in rs]

    rng = np.random.default_rng(5)
    e = rng.normal(0, 0.01, 20001)
    r = np.empty_like(e)
    r[0] = e[0]
    for i in range(1, e.size):
        r[i] = 0.7 * r[i - 1] + e[i]
    n = e.size - 1
    at_truth = n * (np.log(2 * np.pi * np.mean(e[1:] ** 2)) + 1)  # phi = 0.7, the innovations' own variance
    assert at_truth - 10 < ar1_neg2ll(F(r)) <= at_truth  # profiled: as likely or more, by a chi-square(2)-sized gap
    white = n * (np.log(2 * np.pi * np.mean(r[1:] ** 2)) + 1)
    assert ar1_neg2ll(F(r)) < white - 5000  # the correlation is seen
    assert ar1_neg2ll(F(r, r)) == pytest.approx(2 * ar1_neg2ll(F(r)))


def test_the_command_refuses_a_law_the_step_fit_does_not_serve(tmp_path, capsys):
    from frictionlab.cli import main

    assert main(["record", str(tmp_path / "absent.txt"), "--laws", "coulomb"]) == 2
    err = capsys.readouterr().err
    assert "--laws: coulomb is not a state law of the quasi-static slider" in err and "Traceback" not in err
