"""The batch engine agrees with frictionlab.simulate (exact and ode), scene by scene, stick included."""
import math

import numpy as np
import pytest

import frictionlab as fl
from frictionlab.core.errors import (
    FrictionLabError,
    ParameterError,
    SceneError,
    SolverError,
)
from frictionlab.physics.registry import get_law
from frictionlab.physics.scene import (
    ConstantArea,
    G,
    GrowthArea,
    HalfSineArea,
    HalfSineNormal,
    HertzNormal,
    Scene,
    WeightNormal,
)
from frictionlab.solve.batch import SceneBatch, simulate_batch
from frictionlab.solve.plan import make_plan
from frictionlab.solve.solvers import stick

M, R = 0.046, 0.0213


def oblique(speed, angle, e=0.6, tc=450e-6, duration=None):
    """Golf ball on a rigid target: half-sine normal force, slip coupling (stick = rolling)."""
    vn, vt = speed * math.cos(angle), speed * math.sin(angle)
    return Scene(kind="impact", mass=M, u0=vt, duration=duration or tc, radius=R,
                 normal=HalfSineNormal(M * vn * (1 + e), tc), area=HalfSineArea(150e-6, tc),
                 effects=frozenset({"slip-coupling", "spin"}))


def incline(u0, alpha=0.3, area=None, mass=0.02):
    return Scene(kind="incline", mass=mass, u0=u0, duration=1.0, incline=alpha, area=area,
                 normal=WeightNormal(mass * G * math.cos(alpha)), effects=frozenset({"gravity"}))


def paper(u0, peak, tc=500e-6):
    return Scene(kind="impact", mass=M, u0=u0, duration=tc, radius=R, area=HalfSineArea(peak, tc),
                 effects=frozenset({"spin"}))


def check(law, scenes, params, solver, ref, tol, rtol=1e-10):
    br = simulate_batch(law, scenes, params, solver=solver, rtol=rtol)
    for i, s in enumerate(scenes):
        tr = fl.simulate(law, s, params[i], solver=ref, t=br.t if br.t.ndim == 1 else br.t[i], rtol=1e-12)
        V = max(abs(s.u0), 1e-3)
        assert np.allclose(br.u[i], tr.u, rtol=0, atol=tol * V), (i, np.max(np.abs(br.u[i] - tr.u)))
        assert np.allclose(br.v[i], tr.v, rtol=0, atol=tol * V)
        assert np.allclose(br.omega[i], tr.omega, rtol=0, atol=tol * V / R)
        assert np.allclose(br.theta[i], tr.theta, rtol=0, atol=tol * V * s.duration / R)
        Fs = max(np.max(np.abs(tr.force)), 1e-12)
        assert np.allclose(br.force[i], tr.force, rtol=0, atol=max(tol, 1e-9) * Fs * 10)
        if tr.stick_time is None:
            assert math.isnan(br.stick_time[i])
        else:
            assert br.stick_time[i] == pytest.approx(tr.stick_time, rel=max(tol, 1e-12) * 100)
    return br


@pytest.fixture(scope="module")
def rng():
    return np.random.default_rng(7)


def test_coulomb_oblique_impact_with_rolling_matches_exact(rng):
    n = 12
    scenes = [oblique(rng.uniform(20, 60), rng.uniform(0.1, 1.3)) for _ in range(n)]
    params = [{"mu": rng.uniform(0.1, 0.5)} for _ in range(n)]
    br = check("coulomb", scenes, params, "exact", "exact", 1e-12)
    assert 0 < np.sum(~np.isnan(br.stick_time)) < n  # both rolling and sliding-throughout scenes
    after = br.t[None, :] > np.nan_to_num(br.stick_time, nan=np.inf)[:, None]
    assert np.all(br.force[after] == 0.0) and np.all(br.u[after] == 0.0)  # F = 0 once rolling
    for meth in ("DOP853", "RK45"):
        check("coulomb", scenes, params, meth, "exact", 1e-7)


def test_wear_paper_impact_matches_exact(rng):
    n = 8
    scenes = [paper(rng.uniform(10, 30), rng.uniform(100e-6, 300e-6)) for _ in range(n)]
    params = [{"lam": rng.uniform(0.5e6, 2e6)} for _ in range(n)]
    check("wear", scenes, params, "exact", "exact", 1e-13)
    check("wear", scenes, params, "DOP853", "exact", 1e-8)


def test_rk_reproduces_scalar_ode_steps(rng):
    """Same tableau, same scaled problem, same step control: errors match solve_ivp's."""
    scenes = [oblique(rng.uniform(20, 60), rng.uniform(0.1, 1.3)) for _ in range(6)]
    params = [{"mu": rng.uniform(0.1, 0.5)} for _ in range(6)]
    for meth in ("RK45", "DOP853"):
        br = simulate_batch("coulomb", scenes, params, solver=meth, rtol=1e-6)
        for i, s in enumerate(scenes):
            od = fl.simulate("coulomb", s, params[i], solver=f"ode:{meth}", t=br.t, rtol=1e-6)
            ex = fl.simulate("coulomb", s, params[i], solver="exact", t=br.t)
            e_b, e_o = np.max(np.abs(br.u[i] - ex.u)), np.max(np.abs(od.u - ex.u))
            assert e_b <= 2 * e_o + 1e-12 * s.u0


def test_incline_coulomb_sticks_and_holds(rng):
    scenes = [incline(rng.uniform(0.01, 0.3)) for _ in range(10)]
    params = [{"mu": rng.uniform(0.1, 0.8)} for _ in range(10)]
    for solver in ("exact", "DOP853"):
        br = check("coulomb", scenes, params, solver, "exact", 1e-9)
    stuck = ~np.isnan(br.stick_time)
    assert stuck.any() and (~stuck).any()


def test_zero_initial_slip_and_breakaway_area_rate(rng):
    """Start at rest on an incline; area-rate law that lets go while the contact unloads."""
    scenes = [incline(0.0) for _ in range(4)]
    params = [{"mu": m} for m in (0.1, 0.2, 0.4, 0.5)]
    check("coulomb", scenes, params, "exact", "exact", 1e-12)
    check("coulomb", scenes, params, "RK45", "exact", 1e-9)
    imp = [oblique(rng.uniform(20, 60), rng.uniform(0.1, 1.3), duration=540e-6) for _ in range(10)]
    ap = [{"mu": rng.uniform(0.1, 0.5), "eta_prime": rng.uniform(-2e3, 2e3)} for _ in range(10)]
    br = check("area-rate", imp, ap, "exact", "exact", 1e-11)
    check("area-rate", imp, ap, "DOP853", "exact", 1e-6)
    assert br.info["scalar_fallback"] >= 0


def unloading_incline(u0, tc, mu_alpha=0.3, mass=0.02, A0=1e-4, duration=0.2):
    """Block on an incline under a half-sine contact area: with eta' > 0 the area-rate law's capacity
    mu (N + eta' dA/dt) dips below the drive while the area shrinks and recovers once it is gone."""
    return Scene(kind="incline", mass=mass, u0=u0, duration=duration, incline=mu_alpha, area=HalfSineArea(A0, tc),
                 normal=WeightNormal(mass * G * math.cos(mu_alpha)), effects=frozenset({"gravity"}))


def _one_at_a_time(br, i, s, p, V):
    """The scalar exact solve of batch row i (scene s, area-rate parameters p), checked against the row: every
    output within 1e-10 of its scale (slip and velocity: the larger of V and the slip's largest), the same
    number of phases and the same first stop."""
    tr = fl.simulate("area-rate", s, p, solver="exact", t=br.t)
    V = max(V, float(np.max(np.abs(tr.u))))
    r = s.radius or 1.0
    for name, scale in (("u", V), ("v", V), ("omega", V / r), ("theta", V * s.duration / r),
                        ("force", max(np.max(np.abs(tr.force)), 1e-12))):
        err = np.max(np.abs(getattr(br, name)[i] - getattr(tr, name)))
        assert err <= 1e-10 * scale, (i, name, err / scale)
    assert int(br.info["segments_per_scene"][i]) == tr.info["segments"]
    if tr.stick_time is None:
        assert math.isnan(br.stick_time[i])
    else:
        assert br.stick_time[i] == pytest.approx(tr.stick_time, rel=1e-10)
    return tr


def test_exact_breakaway_phases_vectorized_match_scalar(rng):
    """Closed forms after a breakaway run vectorized (no scalar fallback) and equal the scalar exact solver to
    1e-10 of each output's scale, with the same stick and breakaway times and number of phases: a mixture
    of rows that never stick, stick for good, stick and break away, and break away and stick again."""
    imp = [oblique(rng.uniform(10, 60), rng.uniform(0.1, 1.3), duration=540e-6) for _ in range(12)]
    ip = [{"mu": rng.uniform(0.1, 0.5), "eta_prime": rng.uniform(-3e3, 3e3)} for _ in range(12)]
    inc = [unloading_incline(rng.uniform(0.05, 0.3), rng.uniform(0.05, 0.1)) for _ in range(8)]
    cp = [{"mu": rng.uniform(0.4, 0.6), "eta_prime": rng.uniform(0.0, 200.0)} for _ in range(8)]
    seen = set()
    for scenes, params in ((imp, ip), (inc, cp)):
        br = simulate_batch("area-rate", scenes, params, solver="exact", n=301)
        assert br.info["scalar_fallback"] == 0
        for i, s in enumerate(scenes):
            tr = _one_at_a_time(br, i, s, params[i], max(abs(s.u0), 1e-3))
            segs = tr.info["segments"]
            seen.add(segs)
            if tr.stick_time is None:
                continue
            tb = br.info["breakaway_time"][i]
            assert math.isnan(tb) == (segs == 2)
            if segs > 2:  # the scalar solver's breakaway from its own stick (capacity reads t only, not the state)
                plan = make_plan(s, get_law("area-rate"))
                tb_s = stick.breakaway(plan, params[i], tr.stick_time, s.duration, plan.initial_state(), math.copysign(1, s.u0))
                assert tb == pytest.approx(tb_s, rel=1e-10)
    assert seen == {1, 2, 3, 4}  # never sticks, sticks for good, breaks away, breaks away and sticks again


def test_a_start_from_rest_is_solved_in_the_batch_as_one_at_a_time(rng):
    """Scenes at rest at t = 0 (the incline datasets' u0 = 0): stuck for good, sliding at once, or held until the
    contact unloads and then sliding and perhaps sticking again, all in the batch's closed forms (no scalar
    fallback), equal to the scalar exact solver to 1e-10 of each output's scale, with the same number of phases
    and the same first stop."""
    steep = [incline(0.0, alpha=a, area=ConstantArea(1e-4)) for a in (0.2, 0.35, 0.5, 0.7)]
    sp = [{"mu": m, "eta_prime": 0.0} for m in (0.1, 0.5, 0.3, 1.2)]
    unloading = [unloading_incline(0.0, rng.uniform(0.05, 0.1)) for _ in range(5)] + [unloading_incline(0.0, 0.08)]
    up = [{"mu": rng.uniform(0.3, 0.7), "eta_prime": rng.uniform(0.0, 300.0)} for _ in range(5)] + [{"mu": 0.5, "eta_prime": 30.0}]
    seen = set()
    for scenes, params in ((steep, sp), (unloading, up)):
        br = simulate_batch("area-rate", scenes, params, solver="exact", n=301)
        assert br.info["scalar_fallback"] == 0
        for i, s in enumerate(scenes):
            seen.add(_one_at_a_time(br, i, s, params[i], 1e-3).info["segments"])
    assert {1, 2, 3} <= seen  # stuck for good or sliding throughout, held then sliding, sliding then stuck again


def test_lubricated_and_dry_inclines_match_ode(rng):
    lub = [incline(rng.uniform(0, 0.05), alpha=rng.uniform(0.2, 0.6), area=ConstantArea(rng.uniform(1e-4, 4e-4)))
           for _ in range(5)]
    lp = [{"eta": 0.1, "h": rng.uniform(5e-6, 2e-5)} for _ in range(5)]
    check("couette", lub, lp, "exact", "exact", 1e-12)
    check("couette", lub, lp, "RK45", "exact", 1e-5)
    dry = [incline(0.0, alpha=0.5, area=GrowthArea(1e-5, rng.uniform(1e-5, 1e-4))) for _ in range(5)]
    dp = [{"lam": rng.uniform(1e4, 1e5)} for _ in range(5)]
    br = check("wear", dry, dp, "auto", "ode:DOP853", 1e-5)
    assert br.solver == "DOP853"
    with pytest.raises(SolverError):
        simulate_batch("wear", dry, dp, solver="exact")


def test_hertz_normal_uses_integrator(rng):
    scenes = [Scene(kind="impact", mass=M, u0=rng.uniform(5, 30), duration=500e-6, radius=R,
                    area=HalfSineArea(rng.uniform(1e-4, 3e-4), 500e-6), normal=HertzNormal(3e9),
                    effects=frozenset({"slip-coupling"})) for _ in range(5)]
    params = [{"mu": rng.uniform(0.1, 0.5)} for _ in range(5)]
    check("coulomb", scenes, params, "auto", "ode:DOP853", 1e-7)


def test_sweep_arrays_and_shared_params():
    template = oblique(40.0, 0.5)
    u0 = np.linspace(2.0, 30.0, 7)
    batch = SceneBatch.sweep(template, {"u0": u0, "normal.impulse": np.linspace(1.0, 3.0, 7)})
    br = simulate_batch("coulomb", batch, {"mu": 0.3}, solver="exact", n=51)
    assert br.u.shape == (7, 51) and br.stick_time.shape == (7,)
    s3 = batch.scene(3)
    assert s3.u0 == u0[3] and s3.normal.impulse == pytest.approx(2.0)
    tr = fl.simulate("coulomb", s3, {"mu": 0.3}, solver="exact", n=51)
    assert np.allclose(br.trajectory(3).omega, tr.omega, rtol=1e-13)


def test_per_scene_time_grids():
    scenes = [paper(12.0, 130e-6, tc) for tc in (400e-6, 500e-6, 600e-6)]
    br = simulate_batch("wear", scenes, {"lam": 1.8e6}, solver="DOP853", n=31)
    assert br.t.shape == (3, 31) and br.t[2, -1] == pytest.approx(600e-6)


def test_errors_are_one_line():
    with pytest.raises(SceneError):
        simulate_batch("coulomb", [oblique(30, 0.5), incline(0.1)], {"mu": 0.3})
    with pytest.raises(ParameterError, match="scene 1"):
        simulate_batch("coulomb", [oblique(30, 0.5)] * 3, {"mu": np.array([0.3, -1.0, 0.2])})
    with pytest.raises(SolverError):
        simulate_batch("coulomb", [oblique(30, 0.5)], solver="Radau")
    with pytest.raises(FrictionLabError, match="needs"):
        simulate_batch("wear", [incline(0.1)], solver="DOP853")


def test_sweep_in_chunks_on_an_executor_equals_one_call():
    from concurrent.futures import ThreadPoolExecutor

    from frictionlab.solve.sweep import simulate_sweep

    rng = np.random.default_rng(3)
    batch = SceneBatch.sweep(oblique(40.0, 0.5), {"u0": rng.uniform(2, 30, 11)})
    mu = rng.uniform(0.1, 0.5, 11)
    one = simulate_batch("coulomb", batch, {"mu": mu}, solver="DOP853", n=41)
    with ThreadPoolExecutor(2) as ex:
        swept = simulate_sweep("coulomb", batch, {"mu": mu}, solver="DOP853", n=41, executor=ex, chunk=4)
    assert swept.info["chunks"] == 3
    for name in ("u", "v", "omega", "theta", "force", "stick_time"):
        assert np.array_equal(getattr(swept, name), getattr(one, name), equal_nan=True)


@pytest.mark.slow
def test_benchmark_script_runs(capsys):
    """benchmarks/bench_batch.py end to end on a small problem (slow: deselected by default)."""
    import importlib.util
    import pathlib

    path = pathlib.Path(__file__).resolve().parents[1] / "benchmarks" / "bench_batch.py"
    spec = importlib.util.spec_from_file_location("bench_batch", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    mod.main(["--n", "300", "--sample", "10", "--repeats", "1", "--no-numba", "--scaling", "100", "300"])
    out = capsys.readouterr().out
    assert out.count("RATIO plain loop / batch") + out.count("NO RATIO") == 2 and out.count("RATIO batch/bare") == 2
    assert out.count("per-scene cost max/min") == 2


def test_shared_table_model_is_allowed_different_tables_are_not():
    from frictionlab.physics.scene import TableNormal

    tc = 450e-6
    tt = np.linspace(0, tc, 50)
    table = TableNormal(tt, 3000.0 * np.sin(np.pi * tt / tc))
    scenes = [Scene(kind="impact", mass=M, u0=u0, duration=tc, radius=R, normal=table,
                    effects=frozenset({"slip-coupling"})) for u0 in (3.0, 8.0)]
    br = simulate_batch("coulomb", scenes, {"mu": 0.3}, solver="auto", n=41)
    assert br.solver == "DOP853"
    tr = fl.simulate("coulomb", scenes[1], {"mu": 0.3}, solver="ode:DOP853", t=br.t, rtol=1e-10)
    assert np.allclose(br.u[1], tr.u, atol=1e-6 * 8.0)
    other = attrs_evolve(scenes[1], normal=TableNormal(tt, 2.0 * table.N))
    with pytest.raises(SceneError, match="normal.t|normal.N"):
        SceneBatch.from_scenes([scenes[0], other])


def attrs_evolve(obj, **kw):
    import attrs

    return attrs.evolve(obj, **kw)


# --- fast paths against the general ones ---------------------------------------------------------
def test_half_sine_area_alone_is_bitwise_the_area_of_the_full_model():
    """HalfSineArea.value (a law that needs no dA/dt) is the A of __call__, in and outside contact, batch arrays too."""
    area = HalfSineArea(np.array([[1e-4], [2e-4], [3e-4]]), np.array([[4e-4], [5e-4], [6e-4]]))
    t = np.linspace(-1e-4, 7e-4, 57)[None, :]
    assert np.array_equal(area.value(t), area(t)[0])
    one = HalfSineArea(130e-6, 500e-6)
    assert np.array_equal(one.value(t[0]), one(t[0])[0])


def test_normal_integrals_in_place_equal_the_plain_expressions():
    from frictionlab.solve.solvers import exact

    rng = np.random.default_rng(11)
    tc = rng.uniform(4e-4, 5e-4, (6, 1))
    normal = HalfSineNormal(rng.uniform(0.1, 1.0, (6, 1)), tc)
    a = rng.uniform(0.1, 0.5, (6, 1))
    for span in (1.0, 1.3):  # within contact only, and past its end
        t = tc * span * np.linspace(0.0, 1.0, 41)[None, :]
        J, K = exact._normal_integrals(normal, t, a)
        phi, tau = np.pi / tc, np.minimum(t, tc)
        c = a * normal.peak / phi
        assert np.allclose(J, c * (1 - np.cos(phi * tau)), rtol=1e-14, atol=0)
        assert np.allclose(K, c * (tau - np.sin(phi * tau) / phi) + 2 * c * np.maximum(t - tc, 0), rtol=1e-14, atol=0)
        shuffled = rng.permuted(t, axis=1)  # times in any order: the after-contact term is not skipped
        Js, Ks = exact._normal_integrals(normal, shuffled, a)
        order = np.argsort(shuffled, axis=1)
        assert np.array_equal(np.take_along_axis(Ks, order, axis=1), K) and np.array_equal(np.take_along_axis(Js, order, axis=1), J)
        # one time at a time (the plain branch) gives the same numbers
        Jp, Kp = exact._normal_integrals(HalfSineNormal(float(normal.impulse[2, 0]), float(tc[2, 0])), t[2, 7], float(a[2, 0]))
        assert Jp == pytest.approx(J[2, 7], rel=1e-14) and Kp == pytest.approx(K[2, 7], rel=1e-14)


def test_stuck_states_in_place_equal_a_new_array():
    from frictionlab.physics.registry import get_law
    from frictionlab.solve.plan import make_plan
    from frictionlab.solve.solvers import stick

    for scene in (oblique(30.0, 0.5), incline(0.1)):
        plan = make_plan(scene, get_law("coulomb"))
        d = len(plan.states)
        ys = np.random.default_rng(2).uniform(-1, 1, (d, 5, 7))
        t, ts = np.linspace(0.0, 1e-3, 7)[None, :], np.full((5, 1), 2e-4)
        ref, _ = stick.stuck_states(plan, t, ts, ys)
        inplace = ys.copy()
        stick.stuck_states(plan, t, ts, inplace, out=inplace)
        assert np.array_equal(ref, inplace)


def test_outputs_on_one_scaled_grid_equal_the_per_scene_path():
    """The default grid (one grid in scaled time, evaluated as one block) gives bitwise the outputs of the
    general per-scene output path (taken when one scene's grid is not a uniform grid over its span)."""
    rng = np.random.default_rng(5)
    scenes = [oblique(rng.uniform(20, 60), rng.uniform(0.1, 1.3), tc=rng.uniform(4e-4, 5e-4)) for _ in range(6)]
    scenes = [s.__class__(**{**{f: getattr(s, f) for f in ("kind", "mass", "u0", "radius", "normal", "area", "effects")},
                             "duration": s.normal.contact_time}) for s in scenes]
    params = {"mu": rng.uniform(0.1, 0.5, 6)}
    for solver in ("DOP853", "RK45"):
        shared = simulate_batch("coulomb", scenes, params, solver=solver, n=31)
        T = np.array(shared.t)
        odd = T.copy()
        odd[-1, 1:-1] = odd[-1, -1] * np.sort(rng.uniform(0, 1, 29))  # not uniform over its span
        per_row = simulate_batch("coulomb", scenes, params, solver=solver, t=odd)
        for name in ("u", "v", "omega", "theta", "force"):
            assert np.array_equal(getattr(shared, name)[:-1], getattr(per_row, name)[:-1]), (solver, name)


def test_root_at_a_bracket_end_closes_in_a_few_evaluations(monkeypatch):
    """Zero-slip events of rolling impacts whose bracket end is within round-off of the root close in a few
    evaluations, not in bisections (before the safeguard: up to 43 for these scenes), at the same stick times."""
    from frictionlab.solve import compiled, vecrk

    rng = np.random.default_rng(1)
    n = 1000
    V, ang, e, tc = rng.uniform(20, 60, n), np.radians(rng.uniform(5, 75, n)), rng.uniform(0.5, 0.8, n), rng.uniform(4e-4, 5e-4, n)
    template = Scene(kind="impact", mass=M, u0=1.0, duration=tc[0], radius=R, normal=HalfSineNormal(1.0, tc[0]),
                     effects=frozenset({"slip-coupling", "spin"}))
    batch = SceneBatch.sweep(template, {"u0": V * np.sin(ang), "normal.impulse": M * V * np.cos(ang) * (1 + e),
                                        "normal.contact_time": tc, "duration": tc})
    params = {"mu": rng.uniform(0.1, 0.5, n)}
    calls = []  # evaluations per call of the root finder
    inner = vecrk.root_bracketed

    def counted(make_fn, *args):
        calls.append(0)

        def mf(rows):
            fn = make_fn(rows)

            def counted_fn(x):
                calls[-1] += 1
                return fn(x)
            return counted_fn
        return inner(mf, *args)

    monkeypatch.setattr(vecrk, "root_bracketed", counted)
    monkeypatch.setattr(compiled, "available", lambda: False)  # the numpy engine's (the kernel has its own copy)
    br = simulate_batch("coulomb", batch, params, solver="DOP853", rtol=1e-8, n=21)
    assert calls and max(calls) <= 12, calls
    ex = simulate_batch("coulomb", batch, params, solver="exact", n=21)
    rolled = ~np.isnan(ex.stick_time)
    assert np.array_equal(rolled, ~np.isnan(br.stick_time)) and rolled.sum() > n // 2
    assert np.allclose(br.stick_time[rolled], ex.stick_time[rolled], rtol=1e-7)


def test_chunks_written_in_place_equal_one_call(monkeypatch, rng):
    """Chunks integrated straight into the result arrays: scenes that start stuck and break away, stick again,
    and closed forms that hand a scene to the scalar solver give the one-call result bitwise."""
    from frictionlab.solve import batch as B

    cases = [("coulomb", [incline(u0) for u0 in (0.0, 0.05, 0.0, 0.2, 0.1, 0.0, 0.3)],
              [{"mu": m} for m in (0.1, 0.5, 0.4, 0.2, 0.6, 0.2, 0.3)], ("exact", "RK45")),
             ("area-rate", [oblique(rng.uniform(20, 60), rng.uniform(0.1, 1.3), duration=540e-6) for _ in range(7)],
              [{"mu": rng.uniform(0.1, 0.5), "eta_prime": rng.uniform(-2e3, 2e3)} for _ in range(7)], ("exact", "DOP853")),
             ("area-rate", [unloading_incline(u0, tc) for u0, tc in zip((0.1, 0.0, 0.2, 0.25, 0.05, 0.15, 0.3),
                                                                         (0.09, 0.06, 0.07, 0.05, 0.08, 0.1, 0.06))],
              [{"mu": m, "eta_prime": e} for m, e in zip((0.5, 0.45, 0.6, 0.4, 0.55, 0.5, 0.45), (150, 20, 180, 100, 0, 60, 200))],
              ("exact",))]
    for law, scenes, params, solvers in cases:
        for solver in solvers:
            whole = simulate_batch(law, scenes, params, solver=solver, n=17)
            monkeypatch.setattr(B, "CHUNK", 3)
            parts = simulate_batch(law, scenes, params, solver=solver, n=17)
            monkeypatch.undo()
            assert parts.info["chunks"] == 3
            for name in ("u", "v", "omega", "theta", "force", "stick_time", "A", "N"):
                a, b = getattr(whole, name), getattr(parts, name)
                assert (a is None and b is None) or np.array_equal(a, b, equal_nan=True), (law, solver, name)
