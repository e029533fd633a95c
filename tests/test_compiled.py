"""The compiled sliding phases (frictionlab.solve.compiled, numba) against the numpy engine they stand in for:
the same outputs, stick times and steps on random batches of every case they serve, the same
right-hand side as Plan.derivatives, and the numpy engine wherever they do not serve."""
import math

import numpy as np
import pytest

pytest.importorskip("numba")

from frictionlab.physics.law import FrictionLaw, NormalAreaRateForm, ParamSpec, sign  # noqa: E402
from frictionlab.physics.registry import get_law  # noqa: E402
from frictionlab.physics.scene import (  # noqa: E402
    ConstantArea,
    G,
    GrowthArea,
    HalfSineArea,
    HalfSineNormal,
    HertzNormal,
    Scene,
    WeightNormal,
)
from frictionlab.solve import compiled
from frictionlab.solve.batch import SceneBatch, simulate_batch  # noqa: E402
from frictionlab.solve.plan import make_plan  # noqa: E402
from frictionlab.solve.solvers.ode import state_scales  # noqa: E402

M, R = 0.046, 0.0213


def oblique(rng, n, duration_factor=1.0):
    """Golf balls on a rigid target (half-sine normal force and area, slip coupling: they roll)."""
    out = []
    for _ in range(n):
        V, ang, e, tc = rng.uniform(10, 60), rng.uniform(0.1, 1.3), rng.uniform(0.5, 0.8), rng.uniform(400e-6, 500e-6)
        out.append(Scene(kind="impact", mass=M, u0=V * math.sin(ang), duration=tc * duration_factor, radius=R,
                         normal=HalfSineNormal(M * V * math.cos(ang) * (1 + e), tc), area=HalfSineArea(150e-6, tc),
                         effects=frozenset({"slip-coupling", "spin"})))
    return out


def paper(rng, n):
    """The paper's impact: wear law on a half-sine area, spin."""
    return [Scene(kind="impact", mass=M, u0=rng.uniform(8, 30), duration=tc, radius=R,
                  area=HalfSineArea(rng.uniform(100e-6, 300e-6), tc), effects=frozenset({"spin"}))
            for tc in rng.uniform(450e-6, 500e-6, n)]


def unloading_incline(rng, n):
    """Blocks on an incline under a half-sine area: area-rate with eta' > 0 lets go as the area shrinks."""
    out = []
    for _ in range(n):
        a = 0.3
        out.append(Scene(kind="incline", mass=0.02, u0=rng.uniform(0.05, 0.3), duration=0.2, incline=a,
                         area=HalfSineArea(1e-4, rng.uniform(0.05, 0.1)), normal=WeightNormal(0.02 * G * math.cos(a)),
                         effects=frozenset({"gravity"})))
    return out


def incline(rng, n, area=None):
    out = []
    for _ in range(n):
        a = rng.uniform(0.2, 0.6)
        out.append(Scene(kind="incline", mass=0.02, u0=rng.uniform(0.0, 0.3), duration=1.0, incline=a, area=area,
                         normal=WeightNormal(0.02 * G * math.cos(a)), effects=frozenset({"gravity"})))
    return out


def numpy_engine(monkeypatch, *args, **kw):
    with monkeypatch.context() as mp:
        mp.setattr(compiled, "available", lambda: False)
        return simulate_batch(*args, **kw)


def assert_same(a, b, rel=1e-12):
    """Every output within rel of its scale (the two engines differ by the rounding of a sine)."""
    for name in ("u", "v", "omega", "theta", "force", "A", "N"):
        x, y = getattr(a, name), getattr(b, name)
        if y is None:
            assert x is None
            continue
        assert np.array_equal(np.isnan(x), np.isnan(y)), name
        scale = np.nanmax(np.abs(y), axis=1, keepdims=True) + 1e-300
        err = np.nanmax(np.abs(x - y) / scale)
        assert err <= rel, (name, err)
    assert np.array_equal(np.isnan(a.stick_time), np.isnan(b.stick_time))
    ok = ~np.isnan(b.stick_time)
    assert np.allclose(a.stick_time[ok], b.stick_time[ok], rtol=rel, atol=0)


CASES = [
    ("coulomb", lambda rng: oblique(rng, 40), lambda rng, n: [{"mu": m} for m in rng.uniform(0.1, 0.5, n)]),
    ("wear", lambda rng: paper(rng, 40), lambda rng, n: [{"lam": x} for x in rng.uniform(0.5e6, 2e6, n)]),
    ("area-rate", lambda rng: oblique(rng, 30, 1.2),
     lambda rng, n: [{"mu": m, "eta_prime": e} for m, e in zip(rng.uniform(0.1, 0.5, n), rng.uniform(-3e3, 3e3, n))]),
    ("area-rate", lambda rng: unloading_incline(rng, 20),
     lambda rng, n: [{"mu": m, "eta_prime": e} for m, e in zip(rng.uniform(0.4, 0.6, n), rng.uniform(0, 200, n))]),
    ("coulomb", lambda rng: incline(rng, 20), lambda rng, n: [{"mu": m} for m in rng.uniform(0.1, 0.8, n)]),
    ("couette", lambda rng: incline(rng, 10, ConstantArea(2e-4)),
     lambda rng, n: [{"eta": 0.1, "h": h} for h in rng.uniform(5e-6, 2e-5, n)]),
]


@pytest.mark.parametrize("method", ["DOP853", "RK45"])
@pytest.mark.parametrize("case", range(len(CASES)))
def test_compiled_equals_numpy_engine(case, method, monkeypatch):
    law, scenes, params = CASES[case]
    rng = np.random.default_rng(100 + case)
    sc = scenes(rng)
    p = params(rng, len(sc))
    fast = simulate_batch(law, sc, p, solver=method, rtol=1e-8, n=151)
    slow = numpy_engine(monkeypatch, law, sc, p, solver=method, rtol=1e-8, n=151)
    assert fast.info["engine"] == "compiled" and slow.info["engine"] == "numpy"
    assert_same(fast, slow)
    assert fast.info["segments"] == slow.info["segments"]
    assert fast.info["iterations"] == slow.info["iterations"]  # the same steps: as many step attempts


def test_breakaway_and_rolling_cases_are_covered(monkeypatch):
    """The random batches above do exercise what they claim: scenes that roll, and scenes that stick, break
    away (eta' > 0 on unloading) and slide again."""
    rng = np.random.default_rng(100 + 3)
    law, scenes, params = CASES[3]
    sc = scenes(rng)
    br = simulate_batch(law, sc, params(rng, len(sc)), solver="DOP853", n=151)
    assert br.info["segments"] >= 3
    rng = np.random.default_rng(100)
    law, scenes, params = CASES[0]
    sc = scenes(rng)
    assert np.any(~np.isnan(simulate_batch(law, sc, params(rng, len(sc)), solver="DOP853").stick_time))


def test_chunked_batch_is_the_same(monkeypatch):
    """Beyond CHUNK scenes the first phase is integrated straight into the result rows."""
    from frictionlab.solve import batch as batch_module

    rng = np.random.default_rng(5)
    sc = oblique(rng, 30)
    p = {"mu": rng.uniform(0.1, 0.5, 30)}
    monkeypatch.setattr(batch_module, "CHUNK", 8)
    fast = simulate_batch("coulomb", sc, p, solver="DOP853")
    slow = numpy_engine(monkeypatch, "coulomb", sc, p, solver="DOP853")
    assert fast.info["chunks"] == 4
    assert_same(fast, slow)


def test_kernel_rhs_is_plan_derivatives():
    """The kernel's right-hand side (scaled) equals Plan.derivatives on the same scaled problem, through
    contact end, with slip on and against the phase's direction (branch slip)."""
    from frictionlab.solve import compiled_kernel

    rhs = compiled_kernel._rhs
    rng = np.random.default_rng(11)
    cases = [("coulomb", oblique(rng, 6), {"mu": 0.3}), ("wear", paper(rng, 6), {"lam": 1e6}),
             ("area-rate", oblique(rng, 6), {"mu": 0.3, "eta_prime": 2e3}),
             ("coulomb", incline(rng, 6), {"mu": 0.5}), ("couette", incline(rng, 6, ConstantArea(2e-4)),
                                                         {"eta": 0.1, "h": 1e-5})]
    for law_name, scenes, p in cases:
        law = get_law(law_name)
        batch = SceneBatch.from_scenes(scenes)
        plan = make_plan(batch.view(), law)
        n = batch.n
        prep = compiled.prepare(law, plan, p, n)
        assert prep is not None, law_name
        span = np.array([s.duration for s in scenes])
        scale = np.broadcast_to(state_scales(plan, span), (len(plan.states), n))
        cd = tuple(int(c) for c in prep.codes)
        for i, s in enumerate(scenes):
            sp = compiled_kernel._constants(prep.cols, i)
            one = make_plan(s, law)
            for _ in range(20):
                direction = rng.choice([-1.0, 1.0])
                z = rng.normal(size=len(plan.states))
                x = rng.uniform(-0.1, 1.5)
                ssc = scale[:, i]
                want = one.derivatives(p, x * span[i], z * ssc, np.array(direction)) * (span[i] / ssc)
                fac = list(span[i] / ssc) + [0.0] * (3 - len(ssc))
                got = rhs(x, z[0], z[1] if len(z) > 1 else 0.0, sp, cd, span[i], *fac, ssc[0],
                          ssc[1] if len(z) > 1 else 1.0, direction)
                assert got[3]
                np.testing.assert_allclose(got[: len(z)], want, rtol=1e-13, atol=1e-13 * np.max(np.abs(want)))


class PluginCoulomb(FrictionLaw):
    """A plugin law that claims Coulomb's form: served by the numpy engine all the same."""

    name = "plugin-coulomb"
    formula = "F = mu N sign(u)"
    citation = "test"
    params = (ParamSpec("mu", "", 0.3, 0.0, 5.0, 0.3, "friction coefficient"),)
    requires = frozenset({"u", "N"})

    def force(self, p, c):
        return p["mu"] * c.N * sign(c.u)

    def form(self, p):
        return NormalAreaRateForm(a=p["mu"], c=0.0)


def test_refused_where_not_served(monkeypatch):
    rng = np.random.default_rng(3)
    sc = oblique(rng, 5)
    # a plugin law, even with a built-in form
    br = simulate_batch(PluginCoulomb(), sc, {"mu": 0.3}, solver="DOP853")
    assert br.info["engine"] == "numpy"
    ref = simulate_batch("coulomb", sc, {"mu": 0.3}, solver="DOP853")
    assert ref.info["engine"] == "compiled"
    assert_same(br, ref)
    # an unknown scene model: Hertz normal force, growth area
    hertz = [Scene(kind="impact", mass=M, u0=10.0, duration=500e-6, radius=R, area=HalfSineArea(2e-4, 500e-6),
                   normal=HertzNormal(3e9), effects=frozenset({"spin"}))]
    assert simulate_batch("coulomb", hertz, {"mu": 0.3}, solver="DOP853").info["engine"] == "numpy"
    grow = incline(rng, 3, GrowthArea(1e-5, 5e-5))
    assert simulate_batch("couette", grow, {"eta": 0.1, "h": 1e-5}, solver="DOP853").info["engine"] == "numpy"
    # a law with memory, asked directly (the batch refuses such laws before)
    lugre = get_law("lugre")
    plan = make_plan(sc[0], lugre)
    assert compiled.prepare(lugre, plan, lugre.defaults(), 1) is None
    # numba absent
    monkeypatch.setattr(compiled, "available", lambda: False)
    assert simulate_batch("coulomb", sc, {"mu": 0.3}, solver="DOP853").info["engine"] == "numpy"


def test_per_scene_time_grids_are_the_same(monkeypatch):
    """Output times given per scene (not a multiple of one grid) and one shared grid: the kernel takes them as
    batchrk.scaled_grid does."""
    rng = np.random.default_rng(9)
    sc = oblique(rng, 12)
    p = {"mu": rng.uniform(0.1, 0.5, 12)}
    t = np.sort(rng.uniform(0, 1, (12, 40)), axis=1) * np.array([s.duration for s in sc])[:, None]
    t[:, -1] = [s.duration for s in sc]
    t[::3, 0] = 0.0
    for grid in (t, np.linspace(0.0, 400e-6, 50)):
        fast = simulate_batch("coulomb", sc, p, t=grid, solver="DOP853")
        slow = numpy_engine(monkeypatch, "coulomb", sc, p, t=grid, solver="DOP853")
        assert fast.info["engine"] == "compiled"
        assert_same(fast, slow)


def test_a_numba_that_does_not_import_leaves_batches_to_numpy(monkeypatch):
    """An installed numba whose import fails (built for another numpy, say) warns once; batches still run."""
    import sys

    monkeypatch.setattr(compiled, "_status", None)
    import frictionlab.solve

    monkeypatch.setitem(sys.modules, "frictionlab.solve.compiled_kernel", None)  # its import now raises ImportError
    monkeypatch.delattr(frictionlab.solve, "compiled_kernel", raising=False)
    rng = np.random.default_rng(4)
    sc = oblique(rng, 3)
    with pytest.warns(RuntimeWarning, match="numba is installed but does not import"):
        br = simulate_batch("coulomb", sc, {"mu": 0.3}, solver="DOP853")
    assert br.info["engine"] == "numpy" and not compiled.available()
