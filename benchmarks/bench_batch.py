"""Batch engine against a Python loop of solve_ivp, and batch closed forms against bare numpy.

Run:  python benchmarks/bench_batch.py [--n 10000] [--sample 300] [--rtol 1e-8] [--repeats 3]

Everything is measured in this one run on this machine; ratios, not absolute times, are the result.
Scene families (random, seeded):
  coulomb-roll  golf ball on a rigid target, half-sine normal force, slip coupling: Coulomb friction
                with rolling (stick) when slip reaches zero; speeds 20-60 m/s, incidence 5-75 deg from
                the normal, mu 0.1-0.5, restitution 0.5-0.8, contact time 400-500 us.
  wear-paper    the paper's impact: wear law F = lam A u, half-sine area, spin; u0 8-30 m/s,
                A0 100-300 mm^2, lam 0.5e6-2e6 Pa s/m, contact time 450-500 us.
The solve_ivp loop (frictionlab.simulate, solver 'ode:METHOD') is timed on a random subset of the
scenes and extrapolated to all of them (the output says so). Accuracy is the largest error of slip
over the grid against the closed form, relative to u0, on that subset.
"""
from __future__ import annotations

import argparse
import math
import os
import platform
import time

import numpy as np
from scipy.special import ive

import frictionlab as fl
from frictionlab.batch import SceneBatch, simulate_batch
from frictionlab.scene import HalfSineArea, HalfSineNormal, Scene

M, R = 0.046, 0.0213
NT = 101


def hardware() -> str:
    from frictionlab.bench import environment

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
    """Wear law on a half-sine area: eq (6) and its Bessel-series integral, inline numpy."""
    v = batch.values
    u0, A0, tc = v["u0"][:, None], v["area.peak"][:, None], v["area.contact_time"][:, None]
    lam = lam[:, None]
    t = tc * np.linspace(0.0, 1.0, NT)[None, :]
    I = 0.4 * M * R * R
    phi = np.pi / tc
    b = lam * A0 / (M * phi)
    x = phi * t
    u = u0 * np.exp(b * np.cos(x) - b)
    w0 = ive(0, b)
    integral = w0 * t
    for k in range(1, 60):
        w = ive(k, b)
        integral = integral + 2.0 * w / (k * phi) * np.sin(k * x)
        if np.all(2.0 * w <= 1e-17 * k * w0):
            break
    J = M * (u0 - u)
    omega = R * J / I
    theta = R * M * (u0 * t - u0 * integral) / I
    F = lam * A0 * np.sin(x) * u
    return u, u.copy(), omega, theta, F


# --- measurements ---------------------------------------------------------------------------------
def rk_vs_loop(name, law, batch, params, args, rng):
    """Batch DOP853 against loops of simulate(ode:METHOD) on a random subset. Batch runs and loop
    chunks alternate, so slow and fast spells of a shared machine hit both alike."""
    n = batch.n
    ex = simulate_batch(law, batch, params, solver="exact", n=NT)
    scale = np.abs(batch.values["u0"])
    sub = rng.choice(n, size=min(args.sample, n), replace=False)
    chunks = np.array_split(sub, args.repeats)
    batch_times, loop_times, errs = [], {m: 0.0 for m in args.loop_methods}, {m: [] for m in args.loop_methods}
    br = None
    for chunk in chunks:
        t, br = median_time(lambda: simulate_batch(law, batch, params, solver="DOP853", rtol=args.rtol, n=NT), 1)
        batch_times.append(t)
        for method in args.loop_methods:
            t0 = clock()
            for i in chunk:
                p = {k: float(v[i]) for k, v in params.items()}
                tr = fl.simulate(law, batch.scene(int(i)), p, solver=f"ode:{method}", rtol=args.rtol,
                                 t=br.t[i] if br.t.ndim == 2 else br.t)
                errs[method].append(np.max(np.abs(tr.u - ex.u[i])) / scale[i])
            loop_times[method] += clock() - t0
    t_batch = float(np.median(batch_times))
    err_batch = np.max(np.abs(br.u - ex.u), axis=1) / scale
    print(f"\n[{name}] {n} scenes x {NT} samples; {int(np.sum(~np.isnan(ex.stick_time)))} scenes stick (roll)")
    print(f"  batch DOP853 rtol={args.rtol:g}: {t_batch:.3f} s ({t_batch / n * 1e6:.1f} us/scene, median of "
          f"{len(batch_times)} runs {', '.join(f'{x:.3f}' for x in batch_times)}); slip error max "
          f"{err_batch.max():.2e}, median {np.median(err_batch):.2e}")
    results = {}
    for method in args.loop_methods:
        dt = loop_times[method]
        est = dt / sub.size * n
        e = np.array(errs[method])
        matched = 1.1 * e.max() >= err_batch[sub].max()  # equal within 10%
        results[method] = est
        print(f"  loop simulate(solver='ode:{method}', rtol={args.rtol:g}): {dt:.2f} s for a random {sub.size} of {n} "
              f"scenes -> extrapolated {est:.1f} s for all; slip error max {e.max():.2e} "
              f"(batch on the same scenes {err_batch[sub].max():.2e}: "
              f"{'batch as accurate or better' if matched else 'batch LESS accurate'})")
        print(f"  RATIO loop/batch ({method}): {est / t_batch:.0f}x  (target >= 100x: {'met' if est / t_batch >= 100 else 'NOT met'})")
    return results, t_batch


def exact_vs_bare(name, law, batch, params, bare, args, rng):
    n = batch.n
    tb, tr_, br, out = [], [], None, None
    for _ in range(max(args.repeats, 5)):  # alternate, so load spells hit both alike
        t, br = median_time(lambda: simulate_batch(law, batch, params, solver="exact", n=NT), 1)
        tb.append(t)
        t, out = median_time(lambda: bare(batch, next(iter(params.values()))), 1)
        tr_.append(t)
    t_batch, t_bare = float(np.median(tb)), float(np.median(tr_))
    diff = max(np.max(np.abs(a - b) / (np.max(np.abs(b)) + 1e-300)) for a, b in
               zip((br.u, br.v, br.omega, br.theta, br.force), out))
    sub = rng.choice(n, size=min(args.sample, n), replace=False)
    t0 = clock()
    for i in sub:
        fl.simulate(law, batch.scene(int(i)), {k: float(v[i]) for k, v in params.items()}, solver="exact",
                    t=br.t[i] if br.t.ndim == 2 else br.t)
    est = (clock() - t0) / sub.size * n
    ratio = t_batch / t_bare
    print(f"\n[{name} closed form] {n} scenes x {NT} samples (u, v, omega, theta, force)")
    print(f"  batch exact: {t_batch:.3f} s = {n * NT / t_batch / 1e6:.2f} M samples/s; bare numpy: {t_bare:.3f} s = "
          f"{n * NT / t_bare / 1e6:.2f} M samples/s; largest relative difference {diff:.1e}")
    print(f"  RATIO batch/bare: {ratio:.2f}x  (target within 2x: {'met' if ratio <= 2 else 'NOT met'})")
    print(f"  loop of simulate(solver='exact'): extrapolated from {sub.size} scenes {est:.1f} s -> batch is {est / t_batch:.0f}x faster")
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
    """Per-scene cost of the numpy batch against batch size: the interpreter overhead is paid per
    step of the whole batch, so it vanishes per scene as the batch grows."""
    print("\n[scaling] batch DOP853 on coulomb-roll, per-scene CPU time by batch size")
    for n in (10, 100, 1000, args.n):
        b, p = coulomb_family(n, rng)
        t, _ = median_time(lambda: simulate_batch("coulomb", b, p, solver="DOP853", rtol=args.rtol, n=NT), args.repeats)
        print(f"  n = {n:>6}: {t / n * 1e6:9.1f} us/scene")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10_000, help="scenes per family")
    ap.add_argument("--sample", type=int, default=300, help="scenes of the solve_ivp loop actually timed")
    ap.add_argument("--rtol", type=float, default=1e-8)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--loop-methods", nargs="+", default=["DOP853", "LSODA"])
    ap.add_argument("--seed", type=int, default=20240605)
    ap.add_argument("--no-numba", dest="numba", action="store_false")
    args = ap.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    print(f"frictionlab batch benchmark; {hardware()}; python {platform.python_version()}")
    print(f"times are CPU seconds of this process (time.process_time); load average at start "
          f"{', '.join(f'{x:.1f}' for x in os.getloadavg())} on {os.cpu_count()} cores")
    print(f"n = {args.n} scenes per family, loop timed on {args.sample}, rtol = {args.rtol:g}, "
          f"median of {args.repeats} repeats, seed {args.seed}")
    cb, cp = coulomb_family(args.n, rng)
    wb, wp = wear_family(args.n, rng)
    rk_vs_loop("coulomb-roll", "coulomb", cb, cp, args, rng)
    rk_vs_loop("wear-paper", "wear", wb, wp, args, rng)
    exact_vs_bare("coulomb-roll", "coulomb", cb, cp, bare_coulomb, args, rng)
    exact_vs_bare("wear-paper", "wear", wb, wp, bare_wear, args, rng)
    scaling(args, rng)


if __name__ == "__main__":
    main()
