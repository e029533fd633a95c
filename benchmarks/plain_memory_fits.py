"""What a careful user writes with scipy alone to fit a law with memory to a built-in dataset: the reference of
``bench_memory_laws.py``, written independently of frictionlab (it reads the dataset's CSV and TOML itself).

Each fit: a float right-hand side with its analytic Jacobian, integrated by solve_ivp's LSODA at rtol 1e-8; a
scan of 125 log-uniform random starts over wide ranges (seeded); ``least_squares`` (trust region, x_scale 'jac',
2-point differences with a relative step of 1e-6) from the two best; the lower chi-square wins. A solve that
fails or takes more than 50,000 right-hand-side calls is penalized (residual 1e4 per point). Scenes:
  incline  m dv/dt = m g sin(alpha) - F, N = m g cos(alpha), from rest;
  impact   m dv/dt = -F, I domega/dt = F r, dtheta/dt = omega, N(t) half-sine of impulse m v_n (1 + e) over t_c;
           the observables are the paper's stated numbers read off a 401-point grid over the contact (peak spin
           and its time by a parabola through the three highest points, spin at t_c, the largest angle).
Laws (per unit normal force, F = N mu):
  LuGre            dz/dt = u - s0 |u| z / g(u), g = mu_c + (mu_s - mu_c) exp(-(u/vs)^2), mu = s0 z + s1 dz/dt + s2 u;
  Dahl             d mu/dt = sigma u |s|^alpha sign(s), s = 1 - mu sign(u)/mu_c;
  rate-and-state   mu = a asinh(u/(2 V0) exp(psi/a)), psi = mu0 + b ln(V0 theta/Dc), V0 = 1 um/s, aging
                   dtheta/dt = 1 - u theta/Dc or slip -(u theta/Dc) ln(u theta/Dc), theta(0) = Dc/1e-15 m/s
                   (steady at rest); the block slides from rest while the drive exceeds the friction at
                   vanishing slip and, once slip reaches zero, stays stuck (the state held).
"""
from __future__ import annotations

import csv
import math
import time
import tomllib
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import least_squares

G = 9.80665
MAX_CALLS = 50_000  # right-hand-side calls a solve may take before it counts as failed (penalized)
V0 = 1e-6
UNITS = {"g": 1e-3, "kg": 1.0, "deg": math.pi / 180, "mm/s": 1e-3, "m/s": 1.0, "us": 1e-6, "s": 1.0, "mm": 1e-3,
         "rpm": 2 * math.pi / 60, "um": 1e-6}
DATA = Path(__file__).resolve().parent.parent / "datasets"


def q(text) -> float:
    if isinstance(text, (int, float)):
        return float(text)
    number, _, unit = str(text).partition(" ")
    return float(number) * UNITS[unit]


def sgn(x: float) -> float:
    return 1.0 if x > 0 else (-1.0 if x < 0 else 0.0)


# --- laws: (mu, dmu/du, dmu/dx, rate, drate/du, drate/dx) at slip u and state x -------------------------
def lugre(p):
    mu_c, mu_s, vs, s0, s1, s2 = p

    def law(u, z):
        e = math.exp(-(u / vs) ** 2)
        g = mu_c + (mu_s - mu_c) * e
        dg = (mu_s - mu_c) * e * (-2 * u / vs**2)
        zd = u - s0 * abs(u) * z / g
        zu = 1 - s0 * z * (sgn(u) * g - abs(u) * dg) / g**2
        zz = -s0 * abs(u) / g
        return s0 * z + s1 * zd + s2 * u, s1 * zu + s2, s0 + s1 * zz, zd, zu, zz

    return law, 0.0


def dahl(p):
    mu_c, sigma, alpha = p

    def law(u, m):
        s = 1 - m * sgn(u) / mu_c
        a = abs(s)
        slope = alpha * a ** (alpha - 1) if a > 0 else 0.0
        return m, 0.0, 1.0, sigma * u * a**alpha * sgn(s), sigma * a**alpha * sgn(s), -sigma * abs(u) * slope / mu_c

    return law, 0.0


def rate_state(slip_law):
    def make(p):
        mu0, a, b, Dc = p

        def law(u, th):
            u = max(u, 1e-15)
            psi = mu0 + b * math.log(V0 * th / Dc)
            w = math.log(u / (2 * V0)) + psi / a
            A = w + math.log1p(math.sqrt(1 + math.exp(-2 * w))) if w > 0 else math.asinh(math.exp(w))
            dA = 1 / math.sqrt(1 + math.exp(-2 * w)) if w > 0 else math.exp(w) / math.sqrt(1 + math.exp(2 * w))
            x = u * th / Dc
            if slip_law:
                rate, d = -x * math.log(x), -(math.log(x) + 1)
                return a * A, a * dA / u, b * dA / th, rate, d * th / Dc, d * u / Dc
            return a * A, a * dA / u, b * dA / th, 1 - x, -th / Dc, -u / Dc

        return law, Dc / 1e-15

    return make


LAWS = {  # name: (law maker, scan ranges (log10 lo, hi) per parameter, bounds)
    "lugre": (lugre, [(-2, 0.3), (-2, 0.3), (-5, 0), (2, 8), (-6, -1), (-4, 0)],
              ([1e-6, 0, 1e-9, 1, 0, 0], [5, 5, 1e3, 1e12, 1e6, 1e6])),
    "dahl": (dahl, [(-2, 0.3), (1, 7), (-1, 0.7)], ([1e-6, 1, 0.1], [5, 1e12, 5])),
    "rate-state-aging": (rate_state(False), [(-2, 0.3), (-4, -0.5), (-4, -0.5), (-8, -1)],
                         ([0, 1e-5, 0, 1e-9], [2, 0.5, 0.5, 1])),
    "rate-state-slip": (rate_state(True), [(-2, 0.3), (-4, -0.5), (-4, -0.5), (-8, -1)],
                        ([0, 1e-5, 0, 1e-9], [2, 0.5, 0.5, 1])),
}


# --- scenes ---------------------------------------------------------------------------------------------
def load(name):
    meta = tomllib.loads((DATA / f"{name}.toml").read_text())
    with open(DATA / f"{name}.csv") as fh:
        rows = [r for r in csv.reader(line for line in fh if not line.startswith("#"))]
    cols = {k: np.array([float(r[i]) for r in rows[1:]]) for i, k in enumerate(rows[0])}
    return meta, cols


def incline(meta, cols, make, rtol):
    sc = meta["scene"]
    m, alpha = q(sc["mass"]), q(sc["incline"])
    drive, N = G * math.sin(alpha), m * G * math.cos(alpha)
    t = cols["t"]
    obs, sigma = cols["v"], q(meta["noise"]["v"])
    stick = make.__name__ == "make"  # rate-and-state: stick events

    def model(p):
        law, x0 = make(p)
        calls = [0]

        def f(_, y):
            calls[0] += 1
            if calls[0] > MAX_CALLS:
                raise ArithmeticError("too many calls")
            u = max(y[0], 1e-15) if stick else y[0]
            mu, _, _, rate, _, _ = law(u, y[1])
            return [drive - N * mu / m, rate]

        def jac(_, y):
            u = max(y[0], 1e-15) if stick else y[0]
            _, mu_u, mu_x, _, r_u, r_x = law(u, y[1])
            return [[-N * mu_u / m, -N * mu_x / m], [r_u, r_x]]

        if stick:  # slides only while the drive exceeds the friction at vanishing slip
            if N * law(1e-15, x0)[0] >= m * drive:
                return np.zeros(t.size)

            def stop(_, y):
                return y[0] + 1e-12

            stop.terminal, stop.direction = True, -1
            sol = solve_ivp(f, (0, t[-1]), [0.0, x0], "LSODA", t_eval=t, jac=jac, rtol=rtol, atol=[1e-9, x0 * 1e-9],
                            events=stop)
            v = np.zeros(t.size)
            v[: sol.y.shape[1]] = np.maximum(sol.y[0], 0.0)
            return v
        sol = solve_ivp(f, (0, t[-1]), [0.0, x0], "LSODA", t_eval=t, jac=jac, rtol=rtol, atol=[1e-9, 1e-12])
        if not sol.success:
            raise ArithmeticError(sol.message)
        return sol.y[0]

    return model, obs, np.full(obs.size, sigma)


def impact(meta, cols, make, rtol):
    sc = meta["scene"]
    m, r, u0 = q(sc["mass"]), q(sc["radius"]), q(sc["u0"])
    inertia = sc.get("inertia_factor", 0.4) * m * r * r
    tc = q(sc["area"]["contact_time"])
    peak = m * q(sc["normal"]["normal_speed"]) * (1 + sc["normal"]["restitution"]) * math.pi / (2 * tc)
    grid = np.linspace(0, tc, 401)
    names = list(meta["stated"])
    obs = np.array([q(meta["stated"][k][0]) for k in names])
    sigma = np.array([q(meta["stated"][k][1]) for k in names])

    def model(p):
        law, x0 = make(p)
        calls = [0]

        def f(t, y):
            calls[0] += 1
            if calls[0] > MAX_CALLS:
                raise ArithmeticError("too many calls")
            N = peak * math.sin(math.pi * t / tc) if t <= tc else 0.0
            mu, _, _, rate, _, _ = law(y[0], y[3])
            F = N * mu
            return [-F / m, F * r / inertia, y[1], rate]

        def jac(t, y):
            N = peak * math.sin(math.pi * t / tc) if t <= tc else 0.0
            _, mu_u, mu_x, _, r_u, r_x = law(y[0], y[3])
            return [[-N * mu_u / m, 0, 0, -N * mu_x / m], [N * mu_u * r / inertia, 0, 0, N * mu_x * r / inertia],
                    [0, 1, 0, 0], [r_u, 0, 0, r_x]]

        sol = solve_ivp(f, (0, tc), [u0, 0.0, 0.0, x0], "LSODA", t_eval=grid, jac=jac, rtol=rtol,
                        atol=[1e-9 * u0, 1e-9 * u0 / r, 1e-9, 1e-12])
        if not sol.success:
            raise ArithmeticError(sol.message)
        w, th = sol.y[1], sol.y[2]
        i = int(np.clip(np.argmax(w), 1, w.size - 2))
        y0, y1, y2 = w[i - 1], w[i], w[i + 1]
        den = y0 - 2 * y1 + y2
        shift = float(np.clip(0.5 * (y0 - y2) / den, -1, 1)) if den < 0 else 0.0
        got = {"omega_peak": y1 - 0.25 * (y0 - y2) * shift if den < 0 else w.max(),
               "t_peak": grid[i] + shift * (grid[1] - grid[0]) if den < 0 else grid[np.argmax(w)],
               "omega_end": w[-1], "theta_max": th.max()}
        return np.array([got[k] for k in names])

    return model, obs, sigma


def plain_fit(law: str, dataset: str, scan: int = 125, runs: int = 2, rtol: float = 1e-8, seed: int = 1):
    """(chi-square, parameters, CPU seconds) of the careful plain fit of ``law`` to ``dataset``."""
    make, ranges, (lo, hi) = LAWS[law]
    meta, cols = load(dataset)
    scene = incline if meta["kind"] == "incline" else impact
    model, obs, sigma = scene(meta, cols, make, rtol)
    lo, hi = np.array(lo, float), np.array(hi, float)

    def residual(p):
        try:
            with np.errstate(all="ignore"):
                r = (model(p) - obs) / sigma
        except (ArithmeticError, ValueError):
            return np.full(obs.size, 1e4)
        return r if np.all(np.isfinite(r)) else np.full(obs.size, 1e4)

    t0 = time.process_time()
    rng = np.random.default_rng(seed)
    scored = []
    for _ in range(scan):
        p = np.clip(10 ** np.array([rng.uniform(a, b) for a, b in ranges]), lo, hi)
        r = residual(p)
        scored.append((float(r @ r), p))
    scored.sort(key=lambda c: c[0])
    best = None
    for _, p in scored[:runs]:
        try:
            fit = least_squares(residual, p, bounds=(lo, hi), x_scale="jac", diff_step=1e-6)
        except ValueError:
            continue
        if best is None or fit.cost < best.cost:
            best = fit
    chi2 = 2 * best.cost if best is not None else scored[0][0]
    return chi2, (best.x if best is not None else scored[0][1]), time.process_time() - t0


if __name__ == "__main__":
    import sys

    print(plain_fit(sys.argv[1], sys.argv[2]))
