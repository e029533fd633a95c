"""Batch engine against what a user writes (a loop of solve_ivp), and batch closed forms against bare numpy.

Run:  python benchmarks/bench_batch.py [--n 10000] [--sample 300] [--rtol 1e-8] [--repeats 3] [--scaling 1000 10000 100000]
      [--no-numba]  (the numpy engine only: no compiled path, no numba comparison)

Everything is measured in this one run on this machine; ratios, not absolute times, are the result.
Times are CPU seconds of this process (time.process_time): on a shared machine other jobs disturb
them far less than wall time. Scene families (random, seeded):
  coulomb-roll  golf ball on a rigid target, half-sine normal force, slip coupling: Coulomb friction
                with rolling (stick) when slip reaches zero; speeds 20-60 m/s, incidence 5-75 deg from
                the normal, mu 0.1-0.5, restitution 0.5-0.8, contact time 400-500 us.
  wear-paper    the paper's impact: wear law F = lam A u, half-sine area, spin; u0 8-30 m/s,
                A0 100-300 mm^2, lam 0.5e6-2e6 Pa s/m, contact time 450-500 us.
1. Batch DOP853 against a loop of scipy's solve_ivp with a plain Python right-hand side written for
   the family (what a user writes without this library), on the same scaled problem (time by the
   contact time, states by the library's state scales), the same method, rtol (= atol) and zero-slip
   event, timed on a random subset and extrapolated (the output says so). Accuracy: the largest slip
   error over the grid against the closed form, relative to u0, on that subset. The ratio is printed
   only when the batch is as accurate (its error not larger, beyond round-off: a relative 1e-6 of the
   error itself); otherwise the benchmark says so and prints no ratio. Target >= 100x. Both engines
   are timed against the same loop when numba is installed: the compiled sliding phases
   (frictionlab.solve.compiled, the default for the built-in laws) and the numpy engine (frictionlab.solve.vecrk,
   every law); the kernel's one-off compile or cache load is timed apart, before anything else.
2. Batch closed forms against bare numpy of the same expressions (the same sine recurrence and
   Bessel weights on both sides). Target: within 1.5x.
3. Per-scene CPU (median of the repeats at every size) and peak memory (tracemalloc: numpy's
   allocations) by batch size, against the size of the results, after one untimed batch of the
   largest size per family (see ``scaling``). Targets: per-scene cost flat within 1.2x from 1k to
   100k scenes; peak <= 2x the results.
4. The share of the numpy engine's batch time spent filling outputs from the dense interpolant.
0. Cold start (first, in fresh processes): import, the first batch (the compiled kernel loaded from numba's
   cache, or compiled with an empty cache) and a warm 10k-scene batch, so one-off costs sit beside the ratios.
"""
from __future__ import annotations

import argparse
import contextlib
import math
import os
import platform
import resource
import time

import numpy as np
from scipy.integrate import solve_ivp
from scipy.special import ive

from frictionlab.physics.scene import HalfSineArea, HalfSineNormal, Scene
from frictionlab.solve import compiled
from frictionlab.solve.batch import SceneBatch, simulate_batch
from frictionlab.solve.solvers.ode import SLIP_MARGIN

M, R = 0.046, 0.0213
NT = 101


def hardware() -> str:
    from frictionlab.pipeline.bench import environment

    env = environment()
    return f"{env['cpu']}, {env['cores']} cores; " + ", ".join(f"{k} {v}" for k, v in env["versions"].items())


def coulomb_family(n, rng):
    V = rng.uniform(20, 60, n)
    ang = np.radians(rng.uniform(5, 75, n))
    e = rng.uniform(0.5, 0.8, n)
    tc = rng.uniform(400e-6, 500e-6, n)
    template = Scene(kind="impact", mass=M, u0=1.0, duration=tc[0], radius=R, normal=HalfSineNormal(1.0, tc[0]),
                     effects=frozenset({"slip-coupling", "spin"}))
    batch = SceneBatch.sweep(template, {"u0": V * np.sin(ang), "normal.impulse": M * V * np.cos(ang) * (1 + e),
                                        "normal.contact_time": tc, "duration": tc})
    return batch, {"mu": rng.uniform(0.1, 0.5, n)}


def wear_family(n, rng):
    tc = rng.uniform(450e-6, 500e-6, n)
    template = Scene(kind="impact", mass=M, u0=12.0, duration=tc[0], radius=R, area=HalfSineArea(130e-6, tc[0]),
                     effects=frozenset({"spin"}))
    batch = SceneBatch.sweep(template, {"u0": rng.uniform(8, 30, n), "area.peak": rng.uniform(100e-6, 300e-6, n),
                                        "area.contact_time": tc, "duration": tc})
    return batch, {"lam": rng.uniform(0.5e6, 2e6, n)}


#: CPU time of this process: on a shared machine other jobs disturb it far less than wall time.
clock = time.process_time


def median_time(fn, repeats):
    times = []
    out = None
    for _ in range(repeats):
        t0 = clock()
        out = fn()
        times.append(clock() - t0)
    return float(np.median(times)), out


# --- bare numpy: the same closed forms, written inline as a user would --------------------------
def bare_coulomb(batch, mu):
    """Coulomb + rolling on a half-sine normal force: slip, spin, angle and force, inline numpy."""
    v = batch.values
    u0, J_n, tc = v["u0"][:, None], v["normal.impulse"][:, None], v["normal.contact_time"][:, None]
    mu = mu[:, None]
    t = tc * np.linspace(0.0, 1.0, NT)[None, :]
    I = 0.4 * M * R * R
    kappa = 1.0 / M + R * R / I
    phi = np.pi / tc
    Np = J_n * np.pi / (2.0 * tc)
    x = 1.0 - u0 * phi / (kappa * mu * Np)
    ts = np.where(x >= -1.0, np.arccos(np.clip(x, -1.0, 1.0)) / phi, np.inf)  # rolling starts
    tt = np.minimum(t, ts)
    c, s = np.cos(phi * tt), np.sin(phi * tt)
    J = mu * Np / phi * (1.0 - c)  # friction impulse while sliding, frozen after
    K = mu * Np / phi * (tt - s / phi) + J * (t - tt)
    vel = u0 - J / M
    omega = R * J / I
    theta = R * K / I
    F = np.where(t <= ts, mu * Np * np.sin(phi * t), 0.0)
    u = np.where(t <= ts, vel - R * omega, 0.0)
    return u, vel, omega, theta, F


def bare_wear(batch, lam):
    """Wear law on a half-sine area: eq (6) and its Bessel-series integral, inline numpy as a careful user
    writes it: every weight in one ive call, sin(k x) by the recurrence sin((k+1)x) = 2 cos(x) sin(kx) -
    sin((k-1)x), stopping at the first negligible term, and every grid-sized product written in place
    (three work arrays, no temporaries in the loop)."""
    v = batch.values
    u0, A0, tc = v["u0"][:, None], v["area.peak"][:, None], v["area.contact_time"][:, None]
    lam = lam[:, None]
    t = tc * np.linspace(0.0, 1.0, NT)[None, :]
    I = 0.4 * M * R * R
    phi = np.pi / tc
    b = lam * A0 / (M * phi)
    x = phi * t
    cos_x = np.cos(x)
    u = cos_x - 1.0
    u *= b
    np.exp(u, out=u)
    u *= u0
    kmax = int(math.ceil(math.sqrt(2.0 * max(float(b.max()), 1.0) * 45.0))) + 20
    k = np.arange(kmax + 1, dtype=float)[:, None, None]
    w = ive(k, b)
    small = (2.0 * w[1:] <= 1e-17 * k[1:] * w[0]).reshape(kmax, -1).all(axis=1)
    last = int(np.argmax(small)) + 1 if small.any() else kmax
    coef = 2.0 * w[1:] / (k[1:] * phi)
    integral = w[0] * t
    two_cos = np.multiply(cos_x, 2.0, out=cos_x)
    s_prev, s_k, tmp = np.zeros_like(x), np.sin(x), np.empty_like(x)
    for j in range(last):
        np.multiply(coef[j], s_k, out=tmp)
        integral += tmp
        if j + 1 < last:  # s_prev becomes sin((k+1)x), in place
            np.multiply(two_cos, s_k, out=tmp)
            np.subtract(tmp, s_prev, out=s_prev)
            s_prev, s_k = s_k, s_prev
    J = M * (u0 - u)
    omega = R * J / I
    integral *= -u0
    integral += u0 * t
    theta = integral
    theta *= R * M / I
    F = np.sin(x, out=x)
    F *= lam * A0
    F *= u
    return u, u.copy(), omega, theta, F


# --- what a user writes: solve_ivp with a plain Python right-hand side ------------------------------
INERTIA = 0.4 * M * R * R


def plain_coulomb(u0, impulse, tc, mu, rtol, method):
    """Coulomb friction on a golf ball that rolls once slip stops; scaled as frictionlab scales it."""
    T, Np, V = tc, impulse * math.pi / (2.0 * tc), abs(u0)
    sv, sw, sth = V, V / R, V * T / R
    d = 1.0 if u0 > 0 else -1.0

    def rhs(s, z):
        t = s * T
        F = mu * d * (Np * math.sin(math.pi * t / tc) if t < tc else 0.0)
        return [-F / M * T / sv, F * R / INERTIA * T / sw, z[1] * sw * T / sth]

    def slip(s, z):  # the library's event: slip past zero by SLIP_MARGIN of its scale
        return (z[0] * sv - R * z[1] * sw) / sv * d + SLIP_MARGIN

    slip.terminal, slip.direction = True, -1
    sol = solve_ivp(rhs, (0.0, 1.0), [u0 / sv, 0.0, 0.0], method=method, t_eval=np.linspace(0.0, 1.0, NT),
                    rtol=rtol, atol=rtol, events=slip)
    u = np.zeros(NT)  # rolling after the stop: slip zero
    u[: sol.y.shape[1]] = sol.y[0] * sv - R * sol.y[1] * sw
    return u


def plain_wear(u0, peak, tc, lam, rtol, method):
    """The paper's impact, wear law F = lam A u on a half-sine area, spin; scaled as frictionlab scales it."""
    T, V = tc, abs(u0)
    sv, sw, sth = V, V / R, V * T / R

    def rhs(s, z):
        t = s * T
        F = lam * (peak * math.sin(math.pi * t / tc) if t < tc else 0.0) * z[0] * sv
        return [-F / M * T / sv, F * R / INERTIA * T / sw, z[1] * sw * T / sth]

    def slip(s, z):
        return z[0] + SLIP_MARGIN

    slip.terminal, slip.direction = True, -1
    sol = solve_ivp(rhs, (0.0, 1.0), [u0 / sv, 0.0, 0.0], method=method, t_eval=np.linspace(0.0, 1.0, NT),
                    rtol=rtol, atol=rtol, events=slip)
    u = np.zeros(NT)
    u[: sol.y.shape[1]] = sol.y[0] * sv
    return u


PLAIN = {"coulomb": (plain_coulomb, ("u0", "normal.impulse", "normal.contact_time")),
         "wear": (plain_wear, ("u0", "area.peak", "area.contact_time"))}


# --- measurements ---------------------------------------------------------------------------------
@contextlib.contextmanager
def numpy_engine():
    """The numpy engine (frictionlab.solve.vecrk) for every law, as without numba."""
    saved = compiled.available
    compiled.available = lambda: False
    try:
        yield
    finally:
        compiled.available = saved


def engines(args):
    """(label, context) of the batch engines to time: the compiled one when numba is there, and numpy."""
    out = []
    if args.numba and compiled.available():
        out.append(("compiled", contextlib.nullcontext))
    out.append(("numpy", numpy_engine))
    return out


def warm_jit(args):
    """Compile or load the compiled kernel once, timed apart (a one-off per machine and numba version)."""
    if not (args.numba and compiled.available()):
        print("compiled engine: " + ("numba not installed" if args.numba else "skipped (--no-numba)")
              + "; the numpy engine serves every batch")
        return
    t0 = time.perf_counter()
    c0 = clock()
    from frictionlab.solve import compiled_kernel

    b, p = coulomb_family(2, np.random.default_rng(0))
    simulate_batch("coulomb", b, p, solver="DOP853", n=NT)
    st = compiled_kernel.kernel.stats
    print(f"compiled engine: numba {__import__('numba').__version__}; one-off import, compile or cache load and first "
          f"call {time.perf_counter() - t0:.2f} s wall, {clock() - c0:.2f} s CPU (kernel cache hits "
          f"{sum(st.cache_hits.values())}, "
          f"misses {sum(st.cache_misses.values())}), not in any timing below")


COLD = """
import json, sys, time
w0, c0 = time.perf_counter(), time.process_time()
import numpy as np
from frictionlab.solve import compiled
from frictionlab.solve.batch import simulate_batch
sys.path.insert(0, {bench!r})
from bench_batch import coulomb_family
if {numpy_only}:
    compiled.available = lambda: False
b, p = coulomb_family(2, np.random.default_rng(0))
w1, c1 = time.perf_counter(), time.process_time()
r = simulate_batch("coulomb", b, p, solver="DOP853", n=101)
w2, c2 = time.perf_counter(), time.process_time()
b, p = coulomb_family(10_000, np.random.default_rng(1))
simulate_batch("coulomb", b, p, solver="DOP853", n=101)
w3, c3 = time.perf_counter(), time.process_time()
print(json.dumps({{"import": [w1 - w0, c1 - c0], "first": [w2 - w1, c2 - c1], "batch10k": [w3 - w2, c3 - c2],
                  "engine": r.info.get("engine")}}))
"""


def cold_start(args):
    """What a fresh process pays before its first batch: importing, then the first (2-scene) batch, which
    with numba loads the compiled kernel from numba's cache (or compiles it, with an empty cache), beside a
    warm 10k-scene batch in the same process; numpy engine alone for comparison. Wall and CPU seconds."""
    import json
    import subprocess
    import sys
    import tempfile

    bench = os.path.dirname(os.path.abspath(__file__))
    runs = [("numpy engine (no numba import)", True, None)]
    if args.numba and compiled.available():
        runs += [("compiled, kernel from numba's cache", False, None),
                 ("compiled, empty cache (compiles)", False, "fresh")]
    print("\n[cold start] a fresh process: import, first batch (2 Coulomb scenes), then one warm 10k-scene batch")
    for label, numpy_only, cache in runs:
        env = dict(os.environ)
        with tempfile.TemporaryDirectory() as tmp:
            if cache:
                env["NUMBA_CACHE_DIR"] = tmp
            code = COLD.format(bench=bench, numpy_only=numpy_only)
            subprocess.run([sys.executable, "-c", code], env=env, capture_output=True)  # a first run fills the cache
            if cache:  # ...except where the compile itself is measured
                env["NUMBA_CACHE_DIR"] = tempfile.mkdtemp(dir=tmp)
            out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
        if out.returncode:
            print(f"  {label}: failed: {out.stderr.strip().splitlines()[-1:]}")
            continue
        r = json.loads(out.stdout.strip().splitlines()[-1])
        print(f"  {label:38s} import {r['import'][0]:.2f} s wall ({r['import'][1]:.2f} CPU); first batch "
              f"{r['first'][0]:.2f} s wall ({r['first'][1]:.2f} CPU); then 10k scenes {r['batch10k'][0]:.2f} s wall "
              f"({r['batch10k'][1]:.2f} CPU; {r['engine']} engine)")


def rk_vs_plain(name, law, batch, params, args, rng):
    """Batch DOP853 (each engine) against a loop of plain solve_ivp on a random subset. Batch runs and loop
    chunks alternate, so slow and fast spells of a shared machine hit both alike."""
    n = batch.n
    ex = simulate_batch(law, batch, params, solver="exact", n=NT)
    scale = np.abs(batch.values["u0"])
    sub = rng.choice(n, size=min(args.sample, n), replace=False)
    chunks = np.array_split(sub, args.repeats)
    plain, keys = PLAIN[law]
    (pname,) = params
    eng = engines(args)
    batch_times, loop_time, errs = {e: [] for e, _ in eng}, 0.0, []
    last = {}
    for label, ctx in eng:  # one untimed run each: the process's allocator warmed as for the scaling section
        with ctx():
            simulate_batch(law, batch, params, solver="DOP853", rtol=args.rtol, n=NT)
    for chunk in chunks:
        for label, ctx in eng:
            last[label] = None  # the previous run's results are freed first, as a loop over batches would (else each
            # run pays page faults for 2x the results' memory)
            with ctx():
                t, last[label] = median_time(
                    lambda: simulate_batch(law, batch, params, solver="DOP853", rtol=args.rtol, n=NT), 1)
            batch_times[label].append(t)
        t0 = clock()
        for i in chunk:
            u = plain(*(float(batch.values[k][i]) for k in keys), float(params[pname][i]), args.rtol, "DOP853")
            errs.append(np.max(np.abs(u - ex.u[i])) / scale[i])
        loop_time += clock() - t0
    est = loop_time / sub.size * n
    e = np.array(errs)
    print(f"\n[{name}] {n} scenes x {NT} samples; {int(np.sum(~np.isnan(ex.stick_time)))} scenes stick (roll)")
    print(f"  plain solve_ivp DOP853 loop, rtol={args.rtol:g}: {loop_time:.2f} s for a random {sub.size} of {n} scenes "
          f"({loop_time / sub.size * 1e6:.0f} us/scene) -> extrapolated {est:.1f} s for all; slip error max "
          f"{e.max():.2e}, median {np.median(e):.2e}")
    ratios = {}
    for label, _ in eng:
        br, times = last[label], batch_times[label]
        t_batch = float(np.median(times))
        err_batch = np.max(np.abs(br.u - ex.u), axis=1) / scale
        matched = err_batch[sub].max() <= e.max() * (1 + 1e-6)  # not larger, beyond round-off in the error itself
        print(f"  batch DOP853, {label} engine ({br.info.get('engine', '?')} ran), rtol={args.rtol:g}: {t_batch:.3f} s "
              f"({t_batch / n * 1e6:.1f} us/scene, median of {len(times)} runs "
              f"{', '.join(f'{x:.3f}' for x in times)}); "
              f"slip error max {err_batch.max():.2e}, median {np.median(err_batch):.2e} (on the loop's scenes: max "
              f"{err_batch[sub].max():.2e}, median {np.median(err_batch[sub]):.2e}); {br.info['nfev'] / n:.0f} "
              "evaluations per scene")
        if not matched:
            print(f"  NO RATIO ({label}): the batch is less accurate than the loop on these scenes "
                  "(accuracy not matched)")
            continue
        ratios[label] = ratio = est / t_batch
        print(f"  RATIO plain loop / batch ({label} engine) at matched accuracy: {ratio:.0f}x  (target >= 100x: "
              f"{'met' if ratio >= 100 else 'NOT met'})")
    return ratios


def exact_vs_bare(name, law, batch, params, bare, args, rng):
    n = batch.n
    tb, tr_, br, out = [], [], None, None
    for _ in range(max(args.repeats, 5)):  # alternate, so load spells hit both alike
        br = out = None  # previous results freed first, on both sides
        t, br = median_time(lambda: simulate_batch(law, batch, params, solver="exact", n=NT), 1)
        tb.append(t)
        t, out = median_time(lambda: bare(batch, next(iter(params.values()))), 1)
        tr_.append(t)
    t_batch, t_bare = float(np.median(tb)), float(np.median(tr_))
    diff = max(np.max(np.abs(a - b) / (np.max(np.abs(b)) + 1e-300)) for a, b in
               zip((br.u, br.v, br.omega, br.theta, br.force), out))
    ratio = t_batch / t_bare
    print(f"\n[{name} closed form] {n} scenes x {NT} samples (u, v, omega, theta, force)")
    print(f"  batch exact: {t_batch:.3f} s ({t_batch / n * 1e6:.1f} us/scene); bare numpy of the same expressions: "
          f"{t_bare:.3f} s ({t_bare / n * 1e6:.1f} us/scene); largest relative difference {diff:.1e}")
    print(f"  RATIO batch/bare: {ratio:.2f}x  (target within 1.5x: {'met' if ratio <= 1.5 else 'NOT met'})")
    if args.numba:
        numba_closed_form(batch, params, t_bare, bare)
    return ratio


def numba_closed_form(batch, params, t_bare, bare):
    """Why numpy and not numba: the same inline Coulomb closed form compiled with numba, for scale."""
    try:
        import numba
    except ImportError:
        print("  numba not installed: compiled comparison skipped")
        return
    if bare is not bare_coulomb:
        return

    @numba.njit(cache=False, fastmath=False)
    def kernel(u0, J_n, tc, mu, out):
        I = 0.4 * M * R * R
        kappa = 1.0 / M + R * R / I
        n, m = out.shape[1], out.shape[2]
        for i in range(n):
            phi = math.pi / tc[i]
            Np = J_n[i] * math.pi / (2.0 * tc[i])
            x = 1.0 - u0[i] * phi / (kappa * mu[i] * Np)
            ts = math.acos(max(x, -1.0)) / phi if x >= -1.0 else math.inf
            for j in range(m):
                t = tc[i] * j / (m - 1)
                tt = min(t, ts)
                J = mu[i] * Np / phi * (1.0 - math.cos(phi * tt))
                K = mu[i] * Np / phi * (tt - math.sin(phi * tt) / phi) + J * (t - tt)
                vel = u0[i] - J / M
                om = R * J / I
                out[1, i, j] = vel
                out[2, i, j] = om
                out[3, i, j] = R * K / I
                out[4, i, j] = mu[i] * Np * math.sin(phi * t) if t <= ts else 0.0
                out[0, i, j] = vel - R * om if t <= ts else 0.0

    v = batch.values
    out = np.empty((5, batch.n, NT))
    args = (v["u0"], v["normal.impulse"], v["normal.contact_time"], params["mu"], out)
    kernel(*args)  # compile
    t_nb, _ = median_time(lambda: kernel(*args), 3)
    print(f"  numba-compiled loop of the same closed form: {t_nb:.3f} s (bare numpy / numba = {t_bare / t_nb:.2f}x)")


def scaling(args, rng):
    """Per-scene CPU and peak memory of batch DOP853 by batch size (automatic chunking beyond
    frictionlab.solve.batch.CHUNK scenes)."""
    import tracemalloc

    from frictionlab.solve import batch as batch_module

    chunk = getattr(batch_module, "CHUNK", None)
    engine = "compiled" if compiled.available() else "numpy"
    print(f"\n[scaling] batch DOP853 ({engine} engine) rtol={args.rtol:g}, per-scene CPU and peak memory by batch size "
          + (f"(chunks of {chunk} scenes)" if chunk else "(no automatic chunking)"))
    print("  one untimed batch of the largest size per family first: glibc returns a process's first batches' 1-2 MiB "
          "temporaries to the system after each batch (4 KiB page faults on every use) until a larger batch has raised "
          "its dynamic mmap threshold; a process that simulates batches is in that state after its first large one")
    for fam, law in ((coulomb_family, "coulomb"), (wear_family, "wear")):
        per, per_user = {}, {}
        b, p = fam(max(args.scaling), rng)
        simulate_batch(law, b, p, solver="DOP853", rtol=args.rtol, n=NT)
        del b, p
        for n in args.scaling:
            b, p = fam(n, rng)
            # every size alike, at least 5 runs, each split into user and system CPU: the system time is the kernel
            # zeroing (and, on a virtual machine, the host backing) the fresh result memory on first touch, which any
            # code that returns new arrays of that size pays, and which on this VM comes in spells
            runs = []
            for _ in range(max(args.repeats, 5)):
                r0 = resource.getrusage(resource.RUSAGE_SELF)
                simulate_batch(law, b, p, solver="DOP853", rtol=args.rtol, n=NT)
                r1 = resource.getrusage(resource.RUSAGE_SELF)
                runs.append((r1.ru_utime - r0.ru_utime, r1.ru_stime - r0.ru_stime))
            total = [u + s for u, s in runs]
            t, t_user = float(np.median(total)), float(np.median([u for u, _ in runs]))
            sys_time = float(np.median([s for _, s in runs]))
            tracemalloc.start()
            r = simulate_batch(law, b, p, solver="DOP853", rtol=args.rtol, n=NT)
            peak = tracemalloc.get_traced_memory()[1]
            tracemalloc.stop()
            size = sum(a.nbytes for a in (r.u, r.v, r.omega, r.theta, r.force, r.stick_time, r.A, r.N) if a is not None)
            del r
            fresh = []  # the floor: first touch of a new block the size of the results, in the same spell
            for _ in range(3):
                t0 = clock()
                np.ones(size // 8)
                fresh.append(clock() - t0)
            per[n], per_user[n] = t / n, t_user / n
            print(f"  {law:8s} n = {n:>7}: {t / n * 1e6:7.1f} us/scene CPU (median of {len(total)}, "
                  f"{min(total) / n * 1e6:.1f}-{max(total) / n * 1e6:.1f}), of it user {t_user / n * 1e6:.1f} and system "
                  f"{sys_time / n * 1e6:.1f}; writing a fresh block the size of the results alone costs "
                  f"{np.median(fresh) / n * 1e6:.1f} us/scene here; peak {peak / 2**20:7.0f} MiB for "
                  f"{size / 2**20:6.0f} MiB of results = {peak / size:.2f}x (target <= 2x: "
                  f"{'met' if peak <= 2 * size else 'NOT met'})")
        sizes = ", ".join(map(str, per))
        spread, spread_user = max(per.values()) / min(per.values()), max(per_user.values()) / min(per_user.values())
        print(f"  {law}: per-scene CPU max/min over {sizes} scenes = {spread:.2f} (target <= 1.2: "
              f"{'met' if spread <= 1.2 else 'NOT met'}); user CPU alone (the engine's work, without the system's first "
              f"touch of fresh result memory) = {spread_user:.2f} ({'met' if spread_user <= 1.2 else 'NOT met'})")


def dense_share(args, rng):
    """How much of the batch's time goes to filling outputs from the dense interpolant."""
    from frictionlab.solve import vecrk

    print(f"\n[dense output] numpy engine: share of batch DOP853 time in vecrk.dense_output and vecrk.fill_dense, "
          f"{args.n} scenes x {NT}")
    for fam, law in ((coulomb_family, "coulomb"), (wear_family, "wear")):
        b, p = fam(args.n, rng)
        spent = {"dense_output": 0.0, "fill_dense": 0.0}
        orig = {k: getattr(vecrk, k) for k in spent}

        def timed(k):
            def fn(*a, **kw):
                t0 = clock()
                try:
                    return orig[k](*a, **kw)
                finally:
                    spent[k] += clock() - t0
            return fn

        try:
            for k in spent:
                setattr(vecrk, k, timed(k))
            with numpy_engine():
                t, _ = median_time(lambda: simulate_batch(law, b, p, solver="DOP853", rtol=args.rtol, n=NT), 1)
        finally:
            for k, f in orig.items():
                setattr(vecrk, k, f)
        print(f"  {law:8s}: {t:.3f} s, interpolant {spent['dense_output'] / t:.0%}, filling outputs "
              f"{spent['fill_dense'] / t:.0%}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10_000, help="scenes per family")
    ap.add_argument("--sample", type=int, default=300, help="scenes of the solve_ivp loop actually timed")
    ap.add_argument("--rtol", type=float, default=1e-8)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--scaling", type=int, nargs="+", default=[1000, 10_000, 100_000], help="batch sizes to scale over")
    ap.add_argument("--seed", type=int, default=20240605)
    ap.add_argument("--no-numba", dest="numba", action="store_false")
    args = ap.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    print(f"frictionlab batch benchmark; {hardware()}; python {platform.python_version()}")
    print(f"times are CPU seconds of this process (time.process_time); load average at start "
          f"{', '.join(f'{x:.1f}' for x in os.getloadavg())} on {os.cpu_count()} cores")
    print(f"n = {args.n} scenes per family, loop timed on {args.sample}, rtol = {args.rtol:g}, "
          f"median of {args.repeats} repeats, seed {args.seed}")
    cold_start(args)
    warm_jit(args)
    cb, cp = coulomb_family(args.n, rng)
    wb, wp = wear_family(args.n, rng)
    rk_vs_plain("coulomb-roll", "coulomb", cb, cp, args, rng)
    rk_vs_plain("wear-paper", "wear", wb, wp, args, rng)
    exact_vs_bare("coulomb-roll", "coulomb", cb, cp, bare_coulomb, args, rng)
    exact_vs_bare("wear-paper", "wear", wb, wp, bare_wear, args, rng)
    dense_share(args, rng)
    with contextlib.nullcontext() if args.numba else numpy_engine():
        scaling(args, rng)
    print(f"\nload average at end {', '.join(f'{x:.1f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
