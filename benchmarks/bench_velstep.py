"""Velocity-step fit: frictionlab's fit against a plain scipy fit written independently of it.

The reference (``plain_fit`` below, numpy and scipy only, nothing of frictionlab) is what a careful scientist
writes for one velocity step: every sample; the step time from the displacement kink (a continuous two-line
fit, ``velstep_records.kink``); the quasi-static slider in m = mu - mu_ss(V1) and psi = ln(V1 theta / Dc),
integrated by ``solve_ivp`` LSODA with its analytic Jacobian from the step on (steady state before it); mu0 and a
linear friction-vs-displacement trend solved by linear least squares inside every evaluation (projected off);
``least_squares`` over a, b, ln Dc, ln k from STARTS (the lowest cost kept); standard errors from the central-
difference Jacobian of all six parameters jointly, scaled by the residual variance (independent samples).

frictionlab's fit is ``fl.fit(law, dataset)`` on a dataset of every sample of the same record with the same step
time and velocities (written to a temporary folder, never into the repository): its defaults fit the trend and
the stiffness, start from a grid, and use the noise model the dataset declares (``--noise``: the data's AR(p),
as ``datasets import velstep`` writes, or AR(1)).

Printed: per record and law the two fits' a, b, a - b, Dc [um], k [1/um] with standard errors and the difference
in units of the combined standard error; the CPU time of frictionlab's fit (warm, the median of --repeats) over
the reference's, measured right before and after it; and the cold start (a new process: import, load, first fit,
with numba's on-disk cache as it is and with an empty one).

    python benchmarks/bench_velstep.py [--records basalt-velstep4,sepiolite-velstep1] [--laws aging,slip]
                                       [--repeats 3] [--noise arp|ar1] [--no-cold]
"""
from __future__ import annotations

import argparse
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import least_squares

sys.path.insert(0, str(Path(__file__).resolve().parent))
import velstep_records  # noqa: E402

#: The reference's starts (a, b, Dc [um]); k starts at the record's loading estimate; each start's budget of
#: evaluations (a record whose slider is not steady before its step can send LSODA into very stiff corners).
STARTS = ((0.01, 0.01, 3.0), (0.01, 0.01, 30.0), (0.01, 0.01, 300.0))
MAX_NFEV = 60
LAWS = {"aging": "rate-state-aging", "slip": "rate-state-slip"}


# --- the reference: plain numpy and scipy -------------------------------------------------------------------------
def _rhs(law, a, b, Dc, k, V1, V2):
    def f(t, y):
        m, psi = y
        V = V1 * math.exp((m - b * psi) / a)
        dpsi = (V1 * math.exp(-psi) - V) / Dc if law == "aging" else -V / Dc * ((m - b * psi) / a + psi)
        return [k * (V2 - V), dpsi]

    def jac(t, y):
        m, psi = y
        V = V1 * math.exp((m - b * psi) / a)
        if law == "aging":
            row = [-V / (a * Dc), (-V1 * math.exp(-psi) + b * V / a) / Dc]
        else:
            L = (m - b * psi) / a + psi
            row = [-V / (a * Dc) * (L + 1), -(-b * V / a * L + V * (1 - b / a)) / Dc]
        return [[-k * V / a, k * b * V / a], row]

    return f, jac


def _model(th, law, t, ts, V1, V2):
    """m(t) of the quasi-static slider for th = (a, b, ln Dc, ln k): 0 before the step time ts."""
    a, b, lDc, lk = th
    f, jac = _rhs(law, a, b, math.exp(lDc), math.exp(lk), V1, V2)
    out = np.zeros_like(t)
    after = t >= ts
    sol = solve_ivp(f, (ts, t[-1]), [0.0, 0.0], method="LSODA", jac=jac, t_eval=t[after], rtol=1e-8, atol=1e-10)
    if not sol.success or sol.y.shape[1] != after.sum():
        raise RuntimeError(sol.message)
    out[after] = sol.y[0]
    return out


def plain_fit(t, x, mu, ts, V1, V2, k0, law):
    """The reference fit: (values {a, b, a-b, Dc, k}, standard errors, CPU seconds, CPU seconds per start)."""
    B = np.column_stack([np.ones_like(t), x - np.interp(ts, t, x)])
    Q, _ = np.linalg.qr(B)
    bad = np.full(t.size, 1.0)

    def res(th):
        try:
            r = mu - _model(th, law, t, ts, V1, V2)
        except (RuntimeError, OverflowError, ValueError):
            return bad
        return r - Q @ (Q.T @ r)

    t0 = time.process_time()
    best = None
    for a, b, Dc in STARTS:
        r = least_squares(res, [a, b, math.log(Dc), math.log(k0)], x_scale=[0.01, 0.01, 1.0, 1.0], method="trf",
                          max_nfev=MAX_NFEV)
        if best is None or r.cost < best.cost:
            best = r
    cpu = time.process_time() - t0
    th = best.x
    steps = (1e-6, 1e-6, 1e-5, 1e-5)
    J = [(_model(th + h * e, law, t, ts, V1, V2) - _model(th - h * e, law, t, ts, V1, V2)) / (2 * h)
         for h, e in zip(steps, np.eye(4))]
    J = np.column_stack(J + [B[:, 0], B[:, 1]])
    r = res(th)
    cov = float(r @ r) / (t.size - J.shape[1]) * np.linalg.inv(J.T @ J)
    se = np.sqrt(np.diag(cov))
    a, b, Dc, k = th[0], th[1], math.exp(th[2]), math.exp(th[3])
    g = np.array([1.0, -1.0, 0, 0, 0, 0])
    values = {"a": a, "b": b, "a-b": a - b, "Dc": Dc, "k": k}
    errors = {"a": se[0], "b": se[1], "a-b": math.sqrt(g @ cov @ g), "Dc": Dc * se[2], "k": k * se[3]}
    return values, errors, cpu, cpu / len(STARTS)


# --- frictionlab ---------------------------------------------------------------------------------------------------
def project_fit(law, path, repeats):
    """(values, errors in um and 1/um, median CPU seconds of ``repeats`` warm fits, the fit)."""
    import frictionlab as fl

    data = fl.load_dataset(path)
    fl.fit(LAWS[law], data)  # warm: numba's kernel loaded, the dataset read
    cpus = []
    for _ in range(repeats):
        t0 = time.process_time()
        f = fl.fit(LAWS[law], data)
        cpus.append(time.process_time() - t0)
    q = f.velstep.rows[0].quantities
    values = {n: q[n].value for n in ("a", "b", "a-b", "Dc", "k")}
    errors = {n: q[n].stderr for n in ("a", "b", "a-b", "Dc", "k")}
    return values, errors, statistics.median(cpus), f


COLD = """
import time, resource
c0, w0 = time.process_time(), time.perf_counter()
import frictionlab as fl
f = fl.fit({law!r}, fl.load_dataset({path!r}))
print(f"{{time.process_time() - c0:.2f}} {{time.perf_counter() - w0:.2f}} {{f.status}}")
"""


def cold_start(law, path, empty_cache: bool) -> str:
    env = dict(os.environ)
    with tempfile.TemporaryDirectory() as cache:
        if empty_cache:
            env["NUMBA_CACHE_DIR"] = cache
        out = subprocess.run([sys.executable, "-c", COLD.format(law=LAWS[law], path=str(path))], env=env,
                             capture_output=True, text=True, check=True).stdout.split()
    return f"{out[0]} CPU s ({out[1]} s wall), status {out[2]}"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--records", default=",".join(velstep_records.RECORDS))
    ap.add_argument("--laws", default="aging,slip")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--noise", default="arp", choices=("arp", "ar1"),
                    help="the datasets' [noise] correlation: the data's AR(p) (as imported) or AR(1)")
    ap.add_argument("--no-cold", action="store_true", help="skip the cold-start measurement")
    args = ap.parse_args(argv)
    raw = velstep_records.raw_folder()
    if raw is None:
        print("the measured records (shared/data/steadystate beside the repository, or FRICTIONLAB_RAW_DATA) are "
              "absent: nothing to measure")
        return 0
    load = os.getloadavg()[0]
    print(f"bench_velstep: {os.cpu_count()} CPUs, load average {load:.1f} at the start; times are CPU seconds")
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        found = {}
        for name in args.records.split(","):
            found[name] = velstep_records.write(folder, name, raw / velstep_records.RECORDS[name], args.noise)
        first = next(iter(found))
        law0 = args.laws.split(",")[0]
        if not args.no_cold:
            print(f"cold start (new process: import, load {first}, one {LAWS[law0]} fit): numba cache as it is "
                  f"{cold_start(law0, folder / f'{first}.toml', False)}; empty numba cache "
                  f"{cold_start(law0, folder / f'{first}.toml', True)}")
        ratios = []
        for name, info in found.items():
            t, x, mu = velstep_records.read(raw / velstep_records.RECORDS[name])
            print(f"\n{name}: {info['n']} samples, step at {info['t_step']:.4f} s, {info['v1']:.4g} -> "
                  f"{info['v2']:.4g} um/s, k start {info['k0']:.3g} 1/um")
            for law in args.laws.split(","):
                ref_before = plain_fit(t, x, mu, info["t_step"], info["v1"], info["v2"], info["k0"], law)
                vp, ep, cpu_p, f = project_fit(law, folder / f"{name}.toml", args.repeats)
                ref_after = plain_fit(t, x, mu, info["t_step"], info["v1"], info["v2"], info["k0"], law)
                vr, er = ref_after[0], ref_after[1]
                ref_cpu = 0.5 * (ref_before[2] + ref_after[2])
                ratios.append(cpu_p / ref_cpu)
                print(f"  {law}: frictionlab {cpu_p:.2f} s a fit; reference {ref_before[2]:.2f} s before, "
                      f"{ref_after[2]:.2f} s after ({ref_after[3]:.2f} s a start, {len(STARTS)} starts); ratio "
                      f"{cpu_p / ref_cpu:.2f}; frictionlab's goodness: {f.goodness.short}")
                print(f"    {'':6} {'frictionlab':>24} {'reference':>24} {'diff / combined SE':>20}")
                for n in ("a", "b", "a-b", "Dc", "k"):
                    comb = math.hypot(ep[n] or math.nan, er[n])
                    d = (vp[n] - vr[n]) / comb if comb > 0 else math.nan
                    pe = f"{ep[n]:.2g}" if ep[n] is not None else "none"
                    print(f"    {n:6} {vp[n]:>13.5g} ± {pe:<8} {vr[n]:>13.5g} ± {er[n]:<8.2g} {d:>+14.2f}")
                notes = [w for w in f.identifiability.warnings if "bound" in w] + list(f.velstep.sign)
                for note in notes:
                    print(f"    ({note})")
        print(f"\nfit-time ratio frictionlab / reference: median {statistics.median(ratios):.2f}, range "
              f"{min(ratios):.2f} to {max(ratios):.2f} over {len(ratios)} fits; load average {os.getloadavg()[0]:.1f} "
              "at the end")
    return 0


if __name__ == "__main__":
    sys.exit(main())
