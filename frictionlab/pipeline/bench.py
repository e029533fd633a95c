"""Work-precision: error against a reference versus median run time, per method and tolerance.

For each scene kind the same law and scene are solved by every method: scipy's RK45, DOP853,
LSODA, Radau and BDF (``simulate(..., solver='ode:METHOD')``) at rtol = atol = 1e-3 ... 1e-12,
the closed form ('exact') and the paper's series where they exist, the batch engine
(``frictionlab.solve.batch``) and, beside the library's ODE path, what a user writes without it: scipy's
solve_ivp with a plain Python right-hand side of the same scaled problem ('scipy:METHOD (plain)').
The closed form and the batch are timed at throughput, per scene in a batch of ``BATCH_SIZE``
different scenes (``varied``: the case's scene and others around it), and drawn on their own axes;
the closed form is also timed as one call (what a fit pays per evaluation), beside the single-call
solvers; every point carries its rtol. The error of a run is the largest,
over slip u, spin omega and rotation angle theta, of the max-norm error on the sample grid
divided by that series' largest magnitude. The reference is the closed form where one exists,
else DOP853 at rtol 1e-13 (checked against Radau at 1e-12; their difference is reported).
Times are CPU seconds of this process (``time.process_time``): other load on a shared machine
disturbs them less than wall time. Each time is the median over repeats of a loop long enough
to be measured (at least ``MIN_LOOP`` seconds); the diagrams draw the spread (fastest to slowest
repeat) as a bar. An error below ``ROUND_OFF`` is drawn on the line 'exact to round-off'.
"""
from __future__ import annotations

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
from .plainref import plain_solver

ODE_METHODS = ("RK45", "DOP853", "LSODA", "Radau", "BDF")
RTOLS = tuple(10.0 ** -k for k in range(3, 13))
QUICK_RTOLS = (1e-3, 1e-6, 1e-9)
BATCH_METHODS = ("DOP853", "RK45")
PLAIN_METHODS = ("DOP853", "LSODA")  # the plain-scipy reference lines
BATCH_SIZE, QUICK_BATCH_SIZE = 10_000, 1_000  # scenes per batch: closed form and batch timed at throughput
#: Methods timed per call (a solve's cost) and methods timed per scene in a batch (throughput): the diagrams
#: draw them on separate axes.
BATCH_COSTS = ("batch:", "exact")
SINGLE_EXACT = "exact, one call"
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


def varied(scene, n: int, seed: int = 0) -> list:
    """The scene and n - 1 others around it: the initial slip (or, from rest, the incline) scaled by factors
    uniform in [0.8, 1.2], so a batch times scenes that differ, not one scene n times (scene 0 is the
    case's own, the one whose error is reported)."""
    import attrs

    rng = np.random.default_rng(seed)
    f = rng.uniform(0.8, 1.2, n - 1)
    if scene.u0 != 0.0:
        return [scene] + [attrs.evolve(scene, u0=scene.u0 * x) for x in f]
    normal = scene.normal
    return [scene] + [attrs.evolve(scene, incline=scene.incline * x,
                                   normal=attrs.evolve(normal, value=normal.value * math.cos(scene.incline * x)
                                                       / math.cos(scene.incline)))
                      for x in f]


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
    many = varied(scene, batch_size)
    for method in BATCH_METHODS:
        for rtol in rtols:  # noqa: B007
            record(f"batch:{method}", rtol,
                   lambda m=method, r=rtol: simulate_batch(law, many, params, solver=m, rtol=r, t=t), per=batch_size,
                   nfev=lambda out: int(out.info["nfev_per_scene"][0]))
    try:  # the closed form: one call (what a fit pays per evaluation), and per scene in a batch
        simulate_batch(law, [scene], params, solver="exact", t=t)
        record(SINGLE_EXACT, None, lambda: simulate(law, scene, params, solver="exact", t=t))
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


#: The cost at the level users care about: fits at each tolerance (``frictionlab.inference.cost.tolerance``).
FIT_CASES = (("impact-golf-v28", ("wear", "area-rate", "coulomb")), ("incline-dry-d10", ("wear", "couette", "coulomb")))
FIT_METHODS, QUICK_FIT_METHODS = ("LSODA", "DOP853"), ("LSODA",)
FIT_RTOLS, QUICK_FIT_RTOLS = (1e-3, 1e-5, 1e-7, 1e-10), (1e-3, 1e-7)


def _steps(progress, total: int):
    """The one-argument callback the measurements call before each item, as ``progress(done, total, label)``
    (core.progress.Progress): done counts the items finished; ``total`` is an estimate, raised if passed."""
    if progress is None:
        return None
    n = [0]

    def step(msg: str, done: bool = False):  # counted as it starts (fitcost also tells when a fit ends)
        if done:
            return
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
        from ..inference.cost.tolerance import fit_tolerance_study

        for dataset, laws in FIT_CASES:
            fit_rows += fit_tolerance_study(laws, dataset, QUICK_FIT_METHODS if quick else FIT_METHODS,
                                            QUICK_FIT_RTOLS if quick else FIT_RTOLS, progress=progress)
    if outer is not None:
        outer(total, total, "done")
    return {"env": env, "settings": settings, "cases": info, "rows": all_rows, "fit_rows": fit_rows}
