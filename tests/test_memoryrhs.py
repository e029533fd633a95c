"""The compiled path of the built-in laws with memory (solve.memoryrhs) against the general one (Plan.derivatives)."""
from __future__ import annotations

import numpy as np
import pytest

import frictionlab as fl
from frictionlab.physics.registry import get_law
from frictionlab.physics.scene import ConstantNormal, Scene, SpringLoad
from frictionlab.solve.memoryrhs import available, phase, served
from frictionlab.solve.plan import make_plan
from frictionlab.solve.solvers import ode
from frictionlab.solve.solvers.stick import vanishing_slip

pytestmark = pytest.mark.skipif(not available(), reason="numba does not import here: no compiled path")

LAWS = {"lugre": dict(sigma1=0.01, sigma2=0.05), "dahl": dict(alpha=0.6), "rate-state-aging": {},
        "rate-state-slip": {}, "rate-state-prz": {}}


def _slider(mass):
    return Scene(kind="spring-slider", mass=1.0, u0=1e-6, duration=10.0, normal=ConstantNormal(1e4),
                 spring=SpringLoad(2000.0, (0.0, 1.0), (1e-6, 1e-5), mass=mass))


def _cases():
    for ds in ("incline-oil-a100", "incline-dry-d10", "impact-golf-v28"):
        for law in LAWS:
            yield law, fl.load_dataset(ds).scene
    for law in ("rate-state-aging", "rate-state-slip", "rate-state-prz"):
        yield law, _slider(3.0)


@pytest.mark.parametrize("law, scene", list(_cases()))
def test_right_hand_side_and_jacobian_agree_with_the_general_path(law, scene):
    rng = np.random.default_rng(1)
    plan = make_plan(scene, get_law(law))
    p = dict(get_law(law).defaults(), **LAWS[law])
    y0 = plan.initial_state(p)
    scale = np.abs(y0) + 0.3
    T = float(scene.duration)
    for direction in ((0.0,) if plan.continuous else (1.0, -1.0)):
        ph = phase(plan, p, direction, float(vanishing_slip(plan)), T, y0, scale, 10**9, slid=False)
        assert ph is not None and ph.y0 is not None
        for _ in range(15):
            y = y0 + rng.normal(size=y0.size) * scale * 0.5
            if "law:theta" in plan.states:
                y[plan.index("law:theta")] = abs(y[plan.index("law:theta")]) + 0.1
            s = rng.uniform(0.0, 1.0)
            z = y / scale
            want = plan.derivatives(p, s * T, y, direction) * T / scale
            np.testing.assert_allclose(ph.f(s, z), want, rtol=1e-13, atol=1e-300)
            J = ph.jac(s, z)
            for j in range(z.size):  # central differences of the compiled right-hand side
                h = 1e-6 * max(abs(z[j]), 1e-3)
                zp, zm = z.copy(), z.copy()
                zp[j] += h
                zm[j] -= h
                col = (ph.f(s, zp) - ph.f(s, zm)) / (2 * h)
                np.testing.assert_allclose(J[:, j], col, rtol=1e-4, atol=1e-6 * (np.abs(J).max() + 1.0))


def _general(monkeypatch):
    monkeypatch.setattr(ode, "_memory_phase", lambda *a, **k: None)


@pytest.mark.parametrize("law, ds, p", [
    ("lugre", "incline-oil-a100", dict(mu_c=0.33, mu_s=5.0, vs=0.078, sigma0=2.3, sigma1=1.1, sigma2=0.19)),
    ("lugre", "impact-golf-v28", {}),
    ("dahl", "incline-oil-a100", dict(mu_c=0.6, sigma=30.0, alpha=2.0)),  # the block stops: the slip turns
    ("dahl", "impact-golf-v28", dict(mu_c=0.5, sigma=3e4, alpha=1.0)),  # the slip turns during the contact
    ("dahl", "incline-dry-d10", dict(mu_c=0.8, sigma=300.0, alpha=1.5)),  # more turns than MAX_TURNS: then mu_d
    ("rate-state-aging", "incline-oil-a100", dict(mu0=0.2)),  # stick events
    ("rate-state-slip", "impact-golf-v28", dict(mu0=0.2)),
    ("rate-state-prz", "incline-oil-a100", dict(mu0=0.2)),
])
def test_solves_agree_with_the_general_path_to_the_tolerance(monkeypatch, law, ds, p):
    d = fl.load_dataset(ds)
    t = d.t if d.t is not None else np.linspace(0.0, d.scene.duration, 201)
    fast = fl.simulate(law, d.scene, p, t=t, rtol=1e-6)
    tight = fl.simulate(law, d.scene, p, t=t, rtol=1e-11)
    _general(monkeypatch)
    ref = fl.simulate(law, d.scene, p, t=t, rtol=1e-10)
    scale = np.abs(ref.v).max()
    assert np.abs(tight.v - ref.v).max() < 1e-7 * scale  # the same solution
    assert np.abs(fast.v - ref.v).max() < 3e-4 * scale  # to the tolerance asked
    for name in ref.law_states:
        s = np.abs(ref.law_states[name]).max() + 1e-300
        assert np.abs(tight.law_states[name] - ref.law_states[name]).max() < 1e-6 * s


def test_dahl_where_the_general_path_runs_out_of_evaluations(monkeypatch):
    """alpha < 1: |s|^alpha is not Lipschitz where s reaches 0; the slid form integrates it in a few hundred calls."""
    d = fl.load_dataset("incline-dry-d10")
    p = dict(mu_c=0.62, sigma=5.6, alpha=0.43)
    tr = fl.simulate("dahl", d.scene, p, t=d.t, rtol=1e-6)
    assert tr.info["nfev"] < 2000
    ref = fl.simulate("dahl", d.scene, p, t=d.t, rtol=1e-11)
    assert np.abs(tr.v - ref.v).max() < 1e-4 * np.abs(ref.v).max()
    _general(monkeypatch)
    with pytest.raises(fl.FrictionLabError, match="more than 50000 right-hand-side evaluations"):
        fl.simulate("dahl", d.scene, p, t=d.t, rtol=1e-11)


def test_what_is_not_served_takes_the_general_path():
    assert not served(make_plan(fl.load_dataset("spring-slider-aging").scene, get_law("rate-state-aging")))
    assert served(make_plan(_slider(3.0), get_law("rate-state-aging")))
    assert not served(make_plan(fl.load_dataset("incline-oil-a100").scene, get_law("stribeck")))


def test_a_law_error_still_comes_from_the_general_path():
    """A value that is not finite on the compiled path reruns the phase on the general one (the law's own error)."""
    d = fl.load_dataset("incline-oil-a100")
    with pytest.raises(fl.FrictionLabError):
        fl.simulate("lugre", d.scene, dict(mu_c=1e-6, mu_s=0.0, vs=1e-9, sigma0=1e12), t=d.t, rtol=1e-6)


@pytest.mark.slow
@pytest.mark.parametrize("ds, careful", [("incline-oil-a100", 93.0), ("incline-oil-a400", 82.63)])
def test_lugre_fit_reaches_the_careful_minimum(ds, careful):
    """The fit that stalled at chi-square 2626 ('does not fit') on the general path's search reaches < 93; on
    incline-oil-a400 the careful plain fit's minimum (82.63, benchmarks/plain_memory_fits.py) has bristles 3.3 decades
    softer than the start, which only the widest grid of starts reaches."""
    r = fl.fit("lugre", ds)
    assert r.ok and r.stats.chisqr < careful


def test_a_dahl_oscillation_past_max_turns_is_integrated_in_mu_d(monkeypatch):
    from frictionlab.solve import memoryrhs

    d = fl.load_dataset("incline-dry-d10")
    p = dict(mu_c=0.8, sigma=300.0, alpha=1.5)  # the block stops and rocks: the slip turns about 18 times
    turns = []
    real = ode._turns
    monkeypatch.setattr(ode, "_turns", lambda *a, **k: turns.append(1) or real(*a, **k))
    few = fl.simulate("dahl", d.scene, p, t=d.t, rtol=1e-8)
    assert turns  # the slid form followed the turns, then gave up: mu_d's own rate from the phase's start
    monkeypatch.setattr(memoryrhs, "MAX_TURNS", 100)
    many = fl.simulate("dahl", d.scene, p, t=d.t, rtol=1e-8)  # every turn followed in the slid form
    assert np.abs(few.v - many.v).max() < 1e-5 * np.abs(many.v).max()


@pytest.mark.parametrize("law", ["rate-state-aging", "rate-state-slip"])
def test_chatter_is_seen_early_with_the_same_error(monkeypatch, law):
    from frictionlab.core.errors import SolverError
    from frictionlab.solve.solvers import segments

    d = fl.load_dataset("incline-oil-a100")
    p = dict(mu0=0.3, a=0.01, b=0.012, Dc=1e-5)  # breaks away at once and sticks again within nanoseconds
    seen = []
    real = segments._chattering
    monkeypatch.setattr(segments, "_chattering", lambda *a: seen.append(real(*a)) or seen[-1])
    with pytest.raises(SolverError, match="chatter") as early:
        fl.simulate(law, d.scene, p, t=d.t, rtol=1e-6)
    assert any(seen) and len(seen) < segments.MAX_SEGMENTS / 4  # stopped long before the segment limit
    monkeypatch.setattr(segments, "_chattering", lambda *a: False)  # the general rule: MAX_SEGMENTS segments
    with pytest.raises(SolverError, match="chatter") as late:
        fl.simulate(law, d.scene, p, t=d.t, rtol=1e-6)
    assert str(early.value) == str(late.value)


def test_a_short_stick_slip_burst_is_not_chatter():
    from frictionlab.solve.solvers.segments import _chattering

    y = np.array([0.0, 1.0])
    fast = [(k * 1e-9, y) for k in range(10)]
    assert _chattering(fast, 1.0, 180)
    assert not _chattering(fast[:-2], 1.0, 180)  # too few cycles yet
    moving = [(k * 1e-9, y * (1 + 1e-3 * k)) for k in range(10)]
    assert not _chattering(moving, 1.0, 180)  # the state changes from cycle to cycle: it may break free
    slow = [(k * 1e-3, y) for k in range(10)]
    assert not _chattering(slow, 1.0, 180)  # at this pace the segments left might reach the end


def test_rate_state_slip_fit_reaches_the_careful_minimum():
    """The careful plain fit (benchmarks/plain_memory_fits.py) reaches chi-square 14029.6 with mu0 and b at 0; the
    search stopped at 14065.2 (b = 0.0087, Dc = 0.021 um), where chi-square jumps by +-3 with the solver's steps at
    rtol 1e-6, until it also drew starts between its grid's levels and refined its lowest ends at rtol 1e-8."""
    r = fl.fit("rate-state-slip", "incline-oil-a200")
    assert r.ok and r.stats.chisqr < 14031


def test_sampled_starts_fill_every_axis_between_the_grid_levels():
    """``_sampled_starts``: the given start first, then a Latin hypercube over the same spans (one point in
    each of ``limit`` equal slices of every axis, in log for positive parameters), inside the bounds."""
    from frictionlab.inference.fitting.model import _law_slots, _sampled_starts, _start_grid

    law = get_law("rate-state-slip")
    tg = fl.make_target(fl.load_dataset("incline-oil-a200"))
    slots = _law_slots(law, [tg], {}, set(), {})
    levels = _start_grid(slots, np.random.default_rng(1), 375, 1.5)
    grid = _sampled_starts(slots, np.random.default_rng(3), 125, 1.5)
    assert len(grid) == 126 and grid[0] == {s.pname: s.value / s.scale for s in slots}
    for s in slots:
        x = np.array([g[s.pname] for g in grid[1:]])
        assert np.all((x >= s.lower / s.scale) & (x <= s.upper / s.scale))
        assert len({g[s.pname] for g in levels[1:]}) <= 4  # the grid's levels
        if s.key != "mu0":  # mu0's span reaches past its upper bound 2, where points are clipped
            u = (np.log10(x / (s.value / s.scale)) + 1.5) / 3.0
            assert sorted(np.floor(u * 125).astype(int)) == list(range(125))
