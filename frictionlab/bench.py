"""Work-precision: error against a reference versus median run time, per method and tolerance.

For each scene kind the same law and scene are solved by every method: scipy's RK45, DOP853,
LSODA, Radau and BDF (``simulate(..., solver='ode:METHOD')``) at rtol = atol = 1e-3 ... 1e-12,
the closed form ('exact') and the paper's series where they exist, and the batch engine
(``frictionlab.batch``, time per scene in a batch of many). The error of a run is the largest,
over slip u, spin omega and rotation angle theta, of the max-norm error on the sample grid
divided by that series' largest magnitude. The reference is the closed form where one exists,
else DOP853 at rtol 1e-13 (checked against Radau at 1e-12; their difference is reported).
Times are CPU seconds of this process (``time.process_time``): other load on a shared machine
disturbs them less than wall time. Each time is the median over repeats of a loop long enough
to be measured (at least ``MIN_LOOP`` seconds).
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

from .errors import FrictionLabError
from .scene import G, ConstantArea, GrowthArea, HalfSineArea, HalfSineNormal, Scene, WeightNormal

ODE_METHODS = ("RK45", "DOP853", "LSODA", "Radau", "BDF")
RTOLS = tuple(10.0 ** -k for k in range(3, 13))
QUICK_RTOLS = (1e-3, 1e-6, 1e-9)
BATCH_METHODS = ("DOP853", "RK45")
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
    """(median, min) CPU seconds per call over repeats, each a loop of at least MIN_LOOP s."""
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
    return float(np.median(samples)), float(np.min(samples)), out


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
    from .solvers import simulate

    try:
        return simulate(law, scene, params, solver="exact", t=t), "exact (closed form)", 0.0
    except FrictionLabError:
        ref = simulate(law, scene, params, solver="ode:DOP853", rtol=REFERENCE_RTOL, t=t)
        check = simulate(law, scene, params, solver="ode:Radau", rtol=CHECK_RTOL, t=t)
        return ref, f"ode:DOP853 at rtol {REFERENCE_RTOL:g}", _error(check, ref)


def measure_case(name, law, params, scene, rtols, repeats, batch_size, n_t=201, progress=None) -> tuple[list, dict]:
    """All rows of one scene kind: dicts with case, method, rtol, error, time (median, min), nfev, status."""
    from .batch import simulate_batch
    from .solvers import simulate

    t = np.linspace(0.0, scene.duration, n_t)
    ref, ref_name, ref_check = reference(law, params, scene, t)
    rows = []

    def record(method, rtol, fn, per=1, nfev=None):
        if progress:
            progress(f"{name}: {method} rtol={rtol if rtol is not None else '-'}")
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                tmed, tmin, out = _time(fn, repeats)
            tr = out.trajectory(0) if hasattr(out, "trajectory") else out
            err = _error(tr, ref)
            n = nfev(out) if nfev else tr.info.get("nfev")
            rows.append({"case": name, "method": method, "rtol": rtol, "error": err, "time_median_s": tmed / per,
                         "time_min_s": tmin / per, "nfev": n, "status": "ok"})
        except FrictionLabError as exc:
            rows.append({"case": name, "method": method, "rtol": rtol, "error": math.nan, "time_median_s": math.nan,
                         "time_min_s": math.nan, "nfev": None, "status": f"failed: {exc}"})

    for solver in ("exact", "series"):
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                simulate(law, scene, params, solver=solver, t=t)
        except FrictionLabError:
            continue
        record(solver, None, lambda s=solver: simulate(law, scene, params, solver=s, t=t))
    for method in ODE_METHODS:
        for rtol in rtols:
            record(f"ode:{method}", rtol, lambda m=method, r=rtol: simulate(law, scene, params, solver=f"ode:{m}",
                                                                              rtol=r, t=t))
    many = [scene] * batch_size
    for method in BATCH_METHODS:
        for rtol in rtols:  # noqa: B007
            record(f"batch:{method}", rtol,
                   lambda m=method, r=rtol: simulate_batch(law, many, params, solver=m, rtol=r, t=t), per=batch_size,
                   nfev=lambda out: int(out.info["nfev_per_scene"][0]))
    try:
        simulate_batch(law, [scene], params, solver="exact", t=t)
        record("batch:exact", None, lambda: simulate_batch(law, many, params, solver="exact", t=t), per=batch_size,
               nfev=lambda out: 0)
    except FrictionLabError:
        pass
    meta = {"reference": ref_name, "reference_check": ref_check, "n_t": n_t, "batch_size": batch_size,
            "stick_time_s": ref.stick_time}
    return rows, meta


#: The cost at the level users care about: fits at each tolerance (``frictionlab.fitcost``).
FIT_CASES = (("impact-golf-v28", ("wear", "area-rate", "coulomb")), ("incline-dry-d10", ("wear", "couette", "coulomb")))
FIT_METHODS, QUICK_FIT_METHODS = ("LSODA", "DOP853"), ("LSODA",)
FIT_RTOLS, QUICK_FIT_RTOLS = (1e-3, 1e-5, 1e-7, 1e-10), (1e-3, 1e-7)


def run_bench(quick: bool = False, progress=None, fits: bool = True) -> dict:
    """Measure every scene kind (and, with ``fits``, the fit-tolerance study); returns
    {'env', 'settings', 'cases': {name: {title, law, params, meta}}, 'rows', 'fit_rows'}."""
    rtols = QUICK_RTOLS if quick else RTOLS
    repeats = 3 if quick else 7
    batch_size = 20 if quick else 200
    env = environment()
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
        from .fitcost import fit_tolerance_study

        for dataset, laws in FIT_CASES:
            fit_rows += fit_tolerance_study(laws, dataset, QUICK_FIT_METHODS if quick else FIT_METHODS,
                                            QUICK_FIT_RTOLS if quick else FIT_RTOLS, progress=progress)
    return {"env": env, "settings": settings, "cases": info, "rows": all_rows, "fit_rows": fit_rows}


# --- writing --------------------------------------------------------------------------------------------
STYLE = {  # method -> (color, marker)
    "ode:RK45": ("#1f77b4", "o"), "ode:DOP853": ("#ff7f0e", "s"), "ode:LSODA": ("#2ca02c", "^"),
    "ode:Radau": ("#d62728", "v"), "ode:BDF": ("#9467bd", "D"), "batch:DOP853": ("#8c564b", "P"),
    "batch:RK45": ("#e377c2", "X"), "exact": ("#000000", "*"), "batch:exact": ("#7f7f7f", "*"),
    "series": ("#bcbd22", "h"),
}


def plot_case(path, name, case, rows, env) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8.5, 6.0), dpi=110)
    floor = 1e-17
    for method in dict.fromkeys(r["method"] for r in rows):
        pts = [r for r in rows if r["method"] == method and r["status"] == "ok"]
        if not pts:
            continue
        color, marker = STYLE.get(method, ("#333333", "o"))
        x = np.maximum([p["error"] for p in pts], floor)
        y = [p["time_median_s"] for p in pts]
        single = len(pts) == 1
        ax.plot(x, y, marker=marker, color=color, ms=11 if single else 6, lw=0 if single else 1.6,
                label=method + (" (one point)" if single else ""))
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("error: max-norm of u, omega, theta vs reference, relative to each series' peak")
    ax.set_ylabel("median CPU time per scene [s]")
    ax.set_title(f"{case['title']}", fontsize=11)
    ax.grid(True, which="major", alpha=0.4)
    ax.grid(True, which="minor", alpha=0.12)
    meta = case["meta"]
    note = (f"reference: {meta['reference']}" + (f" (Radau {CHECK_RTOL:g} differs by {meta['reference_check']:.1e})"
                                                   if meta["reference_check"] else "")
            + f"; one point per rtol {min(r['rtol'] for r in rows if r['rtol']):.0e}..{max(r['rtol'] for r in rows if r['rtol']):.0e}"
            + f"; batch = per scene in a batch of {meta['batch_size']}"
            + f"\n{env['cpu']}, {env['cores']} cores; numpy {env['versions'].get('numpy')}, scipy "
              f"{env['versions'].get('scipy')}; errors below {floor:g} drawn at {floor:g}")
    fig.text(0.01, 0.01, note, fontsize=7.5, color="#444444", va="bottom")
    ax.legend(fontsize=8.5, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    fig.savefig(path)
    plt.close(fig)


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
             "that series' peak; 'batch:*' times are per scene in a batch of identical scenes.", ""]
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

    from .io import atomic_dir

    written = []
    with atomic_dir(out, force=force) as tmp:
        for name, case in result["cases"].items():
            rows = [r for r in result["rows"] if r["case"] == name]
            plot_case(tmp / f"workprecision_{name}.png", name, case, rows, result["env"])
            written.append(f"workprecision_{name}.png")
        fields = ["case", "method", "rtol", "error", "time_median_s", "time_min_s", "nfev", "status"]
        with open(tmp / "workprecision.csv", "w", newline="", encoding="utf-8") as fh:
            w = csv.DictWriter(fh, fieldnames=fields)
            w.writeheader()
            for r in result["rows"]:
                w.writerow({k: ("" if r[k] is None else r[k]) for k in fields})
        md = markdown(result)
        if result.get("fit_rows"):
            from . import fitcost

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
