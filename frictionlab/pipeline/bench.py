"""Work-precision: error against a reference versus median run time, per method and tolerance.

For each scene kind the same law and scene are solved by every method: scipy's RK45, DOP853,
LSODA, Radau and BDF (``simulate(..., solver='ode:METHOD')``) at rtol = atol = 1e-3 ... 1e-12,
the closed form ('exact') and the paper's series where they exist, the batch engine
(``frictionlab.solve.batch``) and, beside the library's ODE path, what a user writes without it: scipy's
solve_ivp with a plain Python right-hand side of the same scaled problem ('scipy:METHOD (plain)').
The closed form and the batch are timed at throughput, per scene in a batch of ``BATCH_SIZE``
scenes (the closed form's evaluation cost, not the fixed cost of one call); every point carries
its rtol. The error of a run is the largest,
over slip u, spin omega and rotation angle theta, of the max-norm error on the sample grid
divided by that series' largest magnitude. The reference is the closed form where one exists,
else DOP853 at rtol 1e-13 (checked against Radau at 1e-12; their difference is reported).
Times are CPU seconds of this process (``time.process_time``): other load on a shared machine
disturbs them less than wall time. Each time is the median over repeats of a loop long enough
to be measured (at least ``MIN_LOOP`` seconds); the diagrams draw the spread (fastest to slowest
repeat) as a bar. An error below ``ROUND_OFF`` is drawn on the line 'exact to round-off'.
"""
from __future__ import annotations

import json
import math
import os
import platform
import time
import warnings
from importlib import metadata

import numpy as np

from ..core.errors import FrictionLabError
from ..physics.scene import (
    ConstantArea,
    G,
    GrowthArea,
    HalfSineArea,
    HalfSineNormal,
    Scene,
    WeightNormal,
)

ODE_METHODS = ("RK45", "DOP853", "LSODA", "Radau", "BDF")
RTOLS = tuple(10.0 ** -k for k in range(3, 13))
QUICK_RTOLS = (1e-3, 1e-6, 1e-9)
BATCH_METHODS = ("DOP853", "RK45")
PLAIN_METHODS = ("DOP853", "LSODA")  # the plain-scipy reference lines
BATCH_SIZE, QUICK_BATCH_SIZE = 10_000, 1_000  # scenes per batch: closed form and batch timed at throughput
ROUND_OFF = 1e-15  # errors below this are drawn as 'exact to round-off'
MIN_LOOP = 0.02  # s of CPU per timed repeat
REFERENCE_RTOL = 1e-13
CHECK_RTOL = 1e-12  # Radau run that checks the reference where no closed form exists
clock = time.process_time


# --- hardware and versions ----------------------------------------------------------------------
def cpu_model() -> str:
    """CPU model name from /proc/cpuinfo (Linux), else platform.processor()."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as fh:
            for line in fh:
                if line.lower().startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown CPU"


def environment() -> dict:
    """Hardware and package versions, for stating next to any timing."""
    versions = {"python": platform.python_version()}
    for pkg in ("frictionlab", "numpy", "scipy", "matplotlib", "numba"):
        try:
            versions[pkg] = metadata.version(pkg)
        except metadata.PackageNotFoundError:
            pass
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return {"cpu": cpu_model(), "cores": cores, "platform": platform.platform(), "versions": versions}


# --- the scene kinds --------------------------------------------------------------------------------
M_BALL, R_BALL = 0.046, 0.0213


def cases() -> dict:
    """name -> (title, law, params, scene); SI throughout."""
    paper = Scene(kind="impact", mass=M_BALL, u0=12.0, duration=500e-6, radius=R_BALL,
                  area=HalfSineArea(130e-6, 500e-6), effects=frozenset({"spin"}))
    a_lub = math.radians(20.0)
    lub = Scene(kind="incline", mass=0.05, u0=0.0, duration=0.1, incline=a_lub, area=ConstantArea(4e-4),
                normal=WeightNormal(0.05 * G * math.cos(a_lub)), effects=frozenset({"gravity"}))
    a_dry = math.radians(30.0)
    dry = Scene(kind="incline", mass=0.02, u0=0.0, duration=1.5, incline=a_dry, area=GrowthArea(1e-5, 2e-5),
                normal=WeightNormal(0.02 * G * math.cos(a_dry)), effects=frozenset({"gravity"}))
    speed, angle, e, tc = 40.0, math.radians(35.0), 0.7, 450e-6
    oblique = Scene(kind="impact", mass=M_BALL, u0=speed * math.sin(angle), duration=1.2 * tc, radius=R_BALL,
                    normal=HalfSineNormal(M_BALL * speed * math.cos(angle) * (1 + e), tc),
                    effects=frozenset({"slip-coupling", "spin"}))
    return {
        "impact-paper": ("Impact of the paper: wear law, V_i = 28 m/s (u0 = 12 m/s, b = 0.81)", "wear",
                         {"lam": 1.81e6}, paper),
        "incline-lubricated": ("Lubricated incline: Couette law, constant area (levels off)", "couette",
                               {"eta": 0.1, "h": 1e-5}, lub),
        "incline-dry": ("Dry incline: wear law, area growing with sliding length (rises, then falls)", "wear",
                        {"lam": 1e4}, dry),
        "impact-oblique": ("Oblique impact: Coulomb with slip coupling, rolls (sticks) mid-contact", "coulomb",
                           {"mu": 0.15}, oblique),
        # a law with memory: LuGre's bristle state (relaxing in ~1e-6 s) integrated with the motion; stiff
        "impact-lugre": ("Oblique impact: LuGre (bristle state, stiff), slip coupling, integrated through zero slip",
                         "lugre", {"mu_c": 0.15, "mu_s": 0.2, "vs": 1.0, "sigma0": 1e4, "sigma1": 0.0, "sigma2": 0.0},
                         oblique),
    }


# --- measuring ----------------------------------------------------------------------------------------
def _time(fn, repeats: int):
    """(median, min, max, result): CPU seconds per call over repeats, each a loop of at least MIN_LOOP s."""
    out = fn()  # warm-up, and the result
    t0 = clock()
    fn()
    once = max(clock() - t0, 1e-7)
    inner = max(1, int(math.ceil(MIN_LOOP / once)))
    samples = []
    for _ in range(repeats):
        t0 = clock()
        for _ in range(inner):
            fn()
        samples.append((clock() - t0) / inner)
    return float(np.median(samples)), float(np.min(samples)), float(np.max(samples)), out


def _error(tr, ref) -> float:
    errs = []
    for name in ("u", "omega", "theta"):
        r = getattr(ref, name)
        size = float(np.max(np.abs(r)))
        if size > 0:
            errs.append(float(np.max(np.abs(getattr(tr, name) - r))) / size)
    return max(errs)


def reference(law, params, scene, t):
    """The closed form if the scene admits one, else DOP853 at rtol 1e-13 (with Radau 1e-12 as a check)."""
    from ..solve.solvers import simulate

    try:
        return simulate(law, scene, params, solver="exact", t=t), "exact (closed form)", 0.0
    except FrictionLabError:
        ref = simulate(law, scene, params, solver="ode:DOP853", rtol=REFERENCE_RTOL, t=t)
        check = simulate(law, scene, params, solver="ode:Radau", rtol=CHECK_RTOL, t=t)
        return ref, f"ode:DOP853 at rtol {REFERENCE_RTOL:g}", _error(check, ref)


def plain_solver(law, params, scene):
    """What a user writes without frictionlab for the four bench cases: solve_ivp on a plain Python
    right-hand side of the same scaled problem (time by the span, velocities by u0 or the drive's
    reach, as ``solvers.ode.state_scales``), with slip reaching zero as a terminal event after which
    the ball rolls (slip 0, spin constant). Returns solve(method, rtol, t) -> Trajectory-like."""
    from types import SimpleNamespace

    from scipy.integrate import solve_ivp

    from ..physics.registry import get_law
    from ..solve.plan import make_plan
    from ..solve.solvers.ode import state_scales

    plan = make_plan(scene, get_law(law))
    T = scene.duration
    sc = state_scales(plan, T)
    m, r = scene.mass, scene.radius or 0.0
    inertia = 0.4 * m * r * r if scene.radius else 1.0
    drive = G * math.sin(scene.incline) if "gravity" in scene.effects else 0.0
    coupled, spin = plan.coupled, plan.has_spin
    area, normal = scene.area, scene.normal
    if law == "wear":
        k = params["lam"]
    elif law == "couette":
        k = params["eta"] / params["h"]
    mu = params.get("mu", 0.0)

    def friction(t, v, u, x):
        if law == "coulomb":
            tc, peak = normal.contact_time, normal.impulse * math.pi / (2.0 * normal.contact_time)
            return mu * (peak * math.sin(math.pi * t / tc) if t < tc else 0.0) * (1.0 if u > 0 else -1.0)
        if isinstance(area, HalfSineArea):
            a = area.peak * math.sin(math.pi * t / area.contact_time) if t < area.contact_time else 0.0
        elif isinstance(area, GrowthArea):
            a = area.initial + area.rate * x
        else:
            a = area.area
        return k * a * u

    names = plan.states

    def rhs(s, z):
        t = s * T
        y = z * sc
        v = y[0]
        u = v - r * y[1] if coupled else v
        F = friction(t, v, u, y[names.index("x")] if "x" in names else 0.0)
        rates = {"v": drive - F / m, "omega": F * r / inertia, "theta": y[1] if spin else 0.0, "x": abs(u)}
        return [rates[n] * T / sc[i] for i, n in enumerate(names)]

    def slip(s, z):
        return (z[0] * sc[0] - r * z[1] * sc[1]) / sc[0] if coupled else z[0]

    slip.terminal, slip.direction = True, -1

    def solve(method, rtol, t):
        y0 = np.array([scene.u0 if n == "v" else 0.0 for n in names])
        sol = solve_ivp(rhs, (0.0, 1.0), y0 / sc, method=method, t_eval=t / T, rtol=rtol, atol=rtol,
                        events=slip if scene.u0 != 0 else None)  # from rest on an incline slip only grows
        reached = sol.y.shape[1]
        Y = np.empty((len(names), t.size))
        Y[:, :reached] = sol.y * sc[:, None]
        if reached < t.size:  # slip stopped: the ball rolls on, spin frozen, angle growing with it
            te, ye = sol.t_events[0][0] * T, sol.y_events[0][0] * sc
            Y[:, reached:] = ye[:, None]
            if spin:
                Y[2, reached:] = ye[2] + ye[1] * (t[reached:] - te)
        omega = Y[1] if spin else np.zeros(t.size)
        u = Y[0] - r * omega if coupled else Y[0].copy()
        u[reached:] = 0.0
        return SimpleNamespace(u=u, omega=omega, theta=Y[2] if spin else np.zeros(t.size),
                               info={"nfev": int(sol.nfev)})

    return solve


def measure_case(name, law, params, scene, rtols, repeats, batch_size, n_t=201, progress=None) -> tuple[list, dict]:
    """All rows of one scene kind: dicts with case, method, rtol, error, time (median, min), nfev, status."""
    from ..solve.batch import simulate_batch
    from ..solve.solvers import simulate

    t = np.linspace(0.0, scene.duration, n_t)
    ref, ref_name, ref_check = reference(law, params, scene, t)
    rows = []

    def record(method, rtol, fn, per=1, nfev=None):
        if progress:
            progress(f"{name}: {method} rtol={rtol if rtol is not None else '-'}")
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                tmed, tmin, tmax, out = _time(fn, repeats)
            tr = out.trajectory(0) if hasattr(out, "trajectory") else out
            err = _error(tr, ref)
            n = nfev(out) if nfev else tr.info.get("nfev")
            rows.append({"case": name, "method": method, "rtol": rtol, "error": err, "time_median_s": tmed / per,
                         "time_min_s": tmin / per, "time_max_s": tmax / per, "nfev": n, "status": "ok"})
        except FrictionLabError as exc:
            rows.append({"case": name, "method": method, "rtol": rtol, "error": math.nan, "time_median_s": math.nan,
                         "time_min_s": math.nan, "time_max_s": math.nan, "nfev": None, "status": f"failed: {exc}"})

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            simulate(law, scene, params, solver="series", t=t)
        record("series", None, lambda: simulate(law, scene, params, solver="series", t=t))
    except FrictionLabError:
        pass
    for method in ODE_METHODS:
        for rtol in rtols:
            record(f"ode:{method}", rtol, lambda m=method, r=rtol: simulate(law, scene, params, solver=f"ode:{m}",
                                                                              rtol=r, t=t))
    plain = plain_solver(law, params, scene) if law in ("coulomb", "wear", "couette") else None  # the four cases
    for method in PLAIN_METHODS if plain else ():
        for rtol in rtols:
            record(f"scipy:{method} (plain)", rtol, lambda m=method, r=rtol: plain(m, r, t))
    many = [scene] * batch_size
    for method in BATCH_METHODS:
        for rtol in rtols:  # noqa: B007
            record(f"batch:{method}", rtol,
                   lambda m=method, r=rtol: simulate_batch(law, many, params, solver=m, rtol=r, t=t), per=batch_size,
                   nfev=lambda out: int(out.info["nfev_per_scene"][0]))
    try:  # the closed form at its evaluation cost: per scene in a batch
        simulate_batch(law, [scene], params, solver="exact", t=t)
        record("exact", None, lambda: simulate_batch(law, many, params, solver="exact", t=t), per=batch_size,
               nfev=lambda out: 0)
    except FrictionLabError:
        pass
    try:  # which engine ran the batch's sliding phases (frictionlab.solve.compiled with numba, else numpy)
        engine = simulate_batch(law, [scene], params, solver=BATCH_METHODS[0], t=t).info.get("engine")
    except FrictionLabError:
        engine = None  # no batch for this law
    meta = {"reference": ref_name, "reference_check": ref_check, "n_t": n_t, "batch_size": batch_size,
            "stick_time_s": ref.stick_time, "batch_engine": engine}
    return rows, meta


#: The cost at the level users care about: fits at each tolerance (``frictionlab.inference.fitcost``).
FIT_CASES = (("impact-golf-v28", ("wear", "area-rate", "coulomb")), ("incline-dry-d10", ("wear", "couette", "coulomb")))
FIT_METHODS, QUICK_FIT_METHODS = ("LSODA", "DOP853"), ("LSODA",)
FIT_RTOLS, QUICK_FIT_RTOLS = (1e-3, 1e-5, 1e-7, 1e-10), (1e-3, 1e-7)


def _steps(progress, total: int):
    """The one-argument callback the measurements call before each item, as ``progress(done, total, label)``
    (core.progress.Progress): done counts the items finished; ``total`` is an estimate, raised if passed."""
    if progress is None:
        return None
    n = [0]

    def step(msg: str):
        n[0] += 1
        progress(n[0] - 1, max(total, n[0]), msg)
    return step


def expected_items(quick: bool, fits: bool) -> int:
    """About how many measurements run_bench makes (series and exact counted for every case)."""
    rtols = QUICK_RTOLS if quick else RTOLS
    per = len(rtols) * (len(ODE_METHODS) + len(BATCH_METHODS)) + 2
    n = sum(per + (len(PLAIN_METHODS) * len(rtols) if law in ("coulomb", "wear", "couette") else 0)
            for _, law, _, _ in cases().values())
    if fits:
        methods, frt = (QUICK_FIT_METHODS, QUICK_FIT_RTOLS) if quick else (FIT_METHODS, FIT_RTOLS)
        n += sum(len(laws) * (len(methods) * len(frt) + 1) for _, laws in FIT_CASES)
    return n


def run_bench(quick: bool = False, progress=None, fits: bool = True) -> dict:
    """Measure every scene kind (and, with ``fits``, the fit-tolerance study); returns
    {'env', 'settings', 'cases': {name: {title, law, params, meta}}, 'rows', 'fit_rows'}.
    progress(done, total, label): told before each measurement (the total is an estimate)."""
    rtols = QUICK_RTOLS if quick else RTOLS
    repeats = 3 if quick else 7
    batch_size = QUICK_BATCH_SIZE if quick else BATCH_SIZE
    env = environment()
    total = expected_items(quick, fits)
    outer, progress = progress, _steps(progress, total)
    all_rows, info = [], {}
    for name, (title, law, params, scene) in cases().items():
        rows, meta = measure_case(name, law, params, scene, rtols, repeats, batch_size, n_t=101 if quick else 201,
                                  progress=progress)
        all_rows += rows
        info[name] = {"title": title, "law": law, "params": params, "meta": meta}
    settings = {"rtols": list(rtols), "atol": "equal to rtol, on the scaled problem", "repeats": repeats,
                "min_loop_s": MIN_LOOP, "quick": quick, "clock": "time.process_time (CPU seconds of this process)",
                "load_average_at_start": list(os.getloadavg()) if hasattr(os, "getloadavg") else None}
    fit_rows = []
    if fits:
        from ..inference.fitcost import fit_tolerance_study

        for dataset, laws in FIT_CASES:
            fit_rows += fit_tolerance_study(laws, dataset, QUICK_FIT_METHODS if quick else FIT_METHODS,
                                            QUICK_FIT_RTOLS if quick else FIT_RTOLS, progress=progress)
    if outer is not None:
        outer(total, total, "done")
    return {"env": env, "settings": settings, "cases": info, "rows": all_rows, "fit_rows": fit_rows}


# --- writing --------------------------------------------------------------------------------------------
STYLE = {  # method -> (color, marker, line style)
    "ode:RK45": ("#1f77b4", "o", "-"), "ode:DOP853": ("#ff7f0e", "s", "-"), "ode:LSODA": ("#2ca02c", "^", "-"),
    "ode:Radau": ("#d62728", "v", "-"), "ode:BDF": ("#9467bd", "D", "-"), "batch:DOP853": ("#8c564b", "P", "-"),
    "batch:RK45": ("#e377c2", "X", "-"), "exact": ("#000000", "*", "-"), "series": ("#bcbd22", "h", "-"),
    "scipy:DOP853 (plain)": ("#ff7f0e", "s", ":"), "scipy:LSODA (plain)": ("#2ca02c", "^", ":"),
}


def plot_case(path, name, case, rows, env) -> None:
    from ..core.display import pyplot

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(9.0, 6.2), dpi=110, layout="constrained")
    floor = ROUND_OFF / 3
    for method in dict.fromkeys(r["method"] for r in rows):
        pts = [r for r in rows if r["method"] == method and r["status"] == "ok"]
        if not pts:
            continue
        color, marker, ls = STYLE.get(method, ("#333333", "o", "-"))
        x = np.array([p["error"] if p["error"] >= ROUND_OFF else floor for p in pts])
        y = np.array([p["time_median_s"] for p in pts])
        spread = np.array([[p["time_median_s"] - p["time_min_s"] for p in pts],
                           [p["time_max_s"] - p["time_median_s"] for p in pts]])
        single = len(pts) == 1
        ax.errorbar(x, y, yerr=spread, marker=marker, color=color, ms=11 if single else 5.5, lw=0 if single else 1.4,
                    ls=ls, elinewidth=0.8, capsize=2, mfc="white" if "plain" in method else color,
                    label=method + (" (one point)" if single else ""))
        for p, xi, yi in zip(pts, x, y):  # each point carries its rtol (log10)
            if p["rtol"]:
                ax.annotate(f"{math.log10(p['rtol']):.0f}", (xi, yi), xytext=(3, 2), textcoords="offset points",
                            fontsize=6, color=color)
    ax.axvline(floor, color="#999999", lw=0.8, ls="--")
    ax.text(floor, ax.get_ylim()[1], " exact to round-off", rotation=90, va="top", ha="right", fontsize=7.5,
            color="#555555")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("error: max-norm of u, omega, theta vs reference, relative to each series' peak")
    ax.set_ylabel("median CPU time per scene [s] (bar: fastest to slowest repeat)")
    ax.set_title(f"{case['title']}", fontsize=11)
    ax.grid(True, which="major", alpha=0.4)
    ax.grid(True, which="minor", alpha=0.12)
    meta = case["meta"]
    rt = [r["rtol"] for r in rows if r["rtol"]]
    note = (f"numbers at points: log10 rtol ({min(rt):.0e}..{max(rt):.0e}, atol = rtol on the scaled problem); "
            f"reference: {meta['reference']}" + (f" (Radau {CHECK_RTOL:g} differs by {meta['reference_check']:.1e})"
                                                 if meta["reference_check"] else "")
            + "\nexact and batch" + (f" ({meta['batch_engine']} engine)" if meta.get("batch_engine") else "")
            + f": per scene in a batch of {meta['batch_size']} (throughput); scipy (plain): solve_ivp "
              "on a plain Python right-hand side, what a user writes without frictionlab"
            + f"\n{env['cpu']}, {env['cores']} cores; numpy {env['versions'].get('numpy')}, scipy "
              f"{env['versions'].get('scipy')}; errors below {ROUND_OFF:g} drawn at the dashed line")
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    fig.text(0.0, 0.0, note, fontsize=7, color="#444444", va="bottom")
    fig.get_layout_engine().set(rect=(0, 0.07, 1, 0.93))
    fig.savefig(path)
    plt.close(fig)


def reading(name, rows) -> str:
    """A few sentences on what one diagram says, from its rows."""
    ok = [r for r in rows if r["status"] == "ok"]

    def at(method, rtol=None):
        return next((r for r in ok if r["method"] == method and (rtol is None or r["rtol"] == rtol)), None)

    rt = 1e-6 if any(r["rtol"] == 1e-6 for r in ok) else max((r["rtol"] for r in ok if r["rtol"]), default=None)
    parts = []
    ex = at("exact")
    if ex:
        parts.append(f"the closed form costs {ex['time_median_s'] * 1e6:.2g} us per scene"
                     + (" and is exact to round-off" if ex["error"] < ROUND_OFF else f" (error {ex['error']:.1e})"))
    se = at("series")
    if se:
        parts.append(f"the paper's series is off by {se['error']:.2g} of the peak")
    if rt:
        lib = {m: at(m, rt) for m in ("ode:LSODA", "ode:DOP853", "scipy:DOP853 (plain)", "batch:DOP853")}
        if lib["ode:DOP853"] and lib["scipy:DOP853 (plain)"]:
            parts.append(f"at rtol {rt:.0e} the library's ode:DOP853 takes {lib['ode:DOP853']['time_median_s'] * 1e3:.2g} ms "
                         f"(error {lib['ode:DOP853']['error']:.1e}) against {lib['scipy:DOP853 (plain)']['time_median_s'] * 1e3:.2g} "
                         f"ms for plain solve_ivp (error {lib['scipy:DOP853 (plain)']['error']:.1e}), "
                         f"{lib['ode:DOP853']['time_median_s'] / lib['scipy:DOP853 (plain)']['time_median_s']:.1f}x")
        if lib["batch:DOP853"] and lib["scipy:DOP853 (plain)"]:
            parts.append(f"the batch engine at the same rtol costs {lib['batch:DOP853']['time_median_s'] * 1e6:.3g} us per "
                         f"scene, {lib['scipy:DOP853 (plain)']['time_median_s'] / lib['batch:DOP853']['time_median_s']:.0f}x "
                         f"less than the plain loop (error {lib['batch:DOP853']['error']:.1e})")
    ode = [r for r in ok if r["method"].startswith("ode:")]
    if ode:
        best = min(ode, key=lambda r: r["time_median_s"] / max(-math.log10(max(r["error"], ROUND_OFF)), 0.5))
        parts.append(f"per digit of accuracy the cheapest ODE point is {best['method']} at rtol {best['rtol']:.0e} "
                     f"(error {best['error']:.1e}, {best['time_median_s'] * 1e3:.2g} ms)")
    return ("Reading: " + "; ".join(parts) + ".") if parts else ""

def _fmt(x, spec=".3g"):
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "-"
    return format(x, spec)


def markdown(result) -> str:
    env, st = result["env"], result["settings"]
    lines = ["# Work-precision", "",
             f"Hardware: {env['cpu']}, {env['cores']} cores; {env['platform']}.",
             "Versions: " + ", ".join(f"{k} {v}" for k, v in env["versions"].items()) + ".",
             f"Times: {st['clock']}, median of {st['repeats']} repeats, each a loop of at least {st['min_loop_s']} s; "
             f"load average at start {st['load_average_at_start']}.",
             f"Tolerances: rtol in {', '.join(f'{r:.0e}' for r in st['rtols'])}; atol {st['atol']}.",
             "Error: the largest over u, omega, theta of the max-norm error on the sample grid, each relative to "
             "that series' peak; 'exact' and 'batch:*' times are per scene in a batch of identical scenes (throughput); "
             "'scipy:* (plain)' is solve_ivp on a plain Python right-hand side of the same scaled problem.", ""]
    for name, case in result["cases"].items():
        meta = case["meta"]
        lines += [f"## {name}", "", case["title"] + ".", "",
                  f"Law `{case['law']}` with {case['params']}; reference: {meta['reference']}"
                  + (f" (Radau at {CHECK_RTOL:g} differs from it by {meta['reference_check']:.1e})" if meta["reference_check"] else "")
                  + (f"; slip sticks at {meta['stick_time_s'] * 1e6:.1f} us" if meta["stick_time_s"] else "") + ".",
                  f"![work-precision {name}](workprecision_{name}.png)", "",
                  "| method | rtol | error | median time [s] | time / best | nfev | status |",
                  "|---|---|---|---|---|---|---|"]
        rows = [r for r in result["rows"] if r["case"] == name]
        lines[-3:-3] = [reading(name, rows), ""]
        best = min((r["time_median_s"] for r in rows if r["status"] == "ok"), default=math.nan)
        for r in rows:
            lines.append(f"| {r['method']} | {_fmt(r['rtol'], '.0e')} | {_fmt(r['error'], '.2e')} | "
                         f"{_fmt(r['time_median_s'], '.3e')} | {_fmt(r['time_median_s'] / best, '.1f')} | "
                         f"{_fmt(r['nfev'], 'd') if isinstance(r['nfev'], int) else '-'} | {r['status']} |")
        lines.append("")
    return "\n".join(lines)


def write_bench(out, result, force: bool = False) -> list[str]:
    """Write PNGs, workprecision.csv, workprecision.md and environment.json into ``out``, whole or not at all."""
    import csv

    from ..core.files import atomic_dir

    written = []
    with atomic_dir(out, force=force) as tmp:
        for name, case in result["cases"].items():
            rows = [r for r in result["rows"] if r["case"] == name]
            plot_case(tmp / f"workprecision_{name}.png", name, case, rows, result["env"])
            written.append(f"workprecision_{name}.png")
        fields = ["case", "method", "rtol", "error", "time_median_s", "time_min_s", "time_max_s", "nfev", "status"]
        with open(tmp / "workprecision.csv", "w", newline="", encoding="utf-8") as fh:
            w = csv.DictWriter(fh, fieldnames=fields)
            w.writeheader()
            for r in result["rows"]:
                w.writerow({k: ("" if r[k] is None else r[k]) for k in fields})
        md = markdown(result)
        if result.get("fit_rows"):
            from ..inference import fitcost

            fit_fields = list(result["fit_rows"][0])
            with open(tmp / "fit_tolerance.csv", "w", newline="", encoding="utf-8") as fh:
                w = csv.DictWriter(fh, fieldnames=fit_fields)
                w.writeheader()
                for r in result["fit_rows"]:
                    w.writerow({k: ("" if r[k] is None else r[k]) for k in fit_fields})
            md += "\n## What the tolerance does to a fit\n\n"
            for ds in dict.fromkeys(r["dataset"] for r in result["fit_rows"]):
                md += f"### {ds}\n\n" + fitcost.markdown([r for r in result["fit_rows"] if r["dataset"] == ds]) + "\n\n"
            written.append("fit_tolerance.csv")
        (tmp / "workprecision.md").write_text(md + "\n", encoding="utf-8")
        meta = {k: result[k] for k in ("env", "settings")}
        meta["cases"] = {k: {**v, "meta": {**v["meta"]}} for k, v in result["cases"].items()}
        (tmp / "environment.json").write_text(json.dumps(meta, indent=2, default=str) + "\n", encoding="utf-8")
        written += ["workprecision.csv", "workprecision.md", "environment.json"]
    return written
