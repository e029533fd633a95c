"""Writing a work-precision study (``frictionlab.pipeline.bench``): one PNG per scene kind with single-call
and batch-throughput costs on separate axes, workprecision.csv/.md, fit_tolerance.csv, environment.json."""
from __future__ import annotations

import json
import math

import numpy as np

from .bench import BATCH_COSTS, CHECK_RTOL, ROUND_OFF, SINGLE_EXACT
from ..core.display import plain_log

STYLE = {  # method -> (color, marker, line style)
    "ode:RK45": ("#1f77b4", "o", "-"), "ode:DOP853": ("#ff7f0e", "s", "-"), "ode:LSODA": ("#2ca02c", "^", "-"),
    "ode:Radau": ("#d62728", "v", "-"), "ode:BDF": ("#9467bd", "D", "-"), "batch:DOP853": ("#8c564b", "P", "-"),
    "batch:RK45": ("#e377c2", "X", "-"), "exact": ("#000000", "*", "-"), SINGLE_EXACT: ("#000000", "*", "-"),
    "series": ("#bcbd22", "h", "-"),
    "scipy:DOP853 (plain)": ("#ff7f0e", "s", ":"), "scipy:LSODA (plain)": ("#2ca02c", "^", ":"),
}


def is_batch_cost(method: str) -> bool:
    """Timed per scene in a batch (throughput), not per call."""
    return method.startswith(BATCH_COSTS[0]) or method == BATCH_COSTS[1]


def _draw(ax, rows, floor) -> None:
    """One line per method: error against median CPU time, bars from fastest to slowest repeat."""
    if not any(r["status"] == "ok" for r in rows):
        ax.text(0.5, 0.5, "no method of this kind applies to this law", ha="center", va="center",
                transform=ax.transAxes, fontsize=9, color="#555555")
        return
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
    ax.set_xscale("log")
    ax.set_yscale("log")
    plain_log(ax.xaxis)
    plain_log(ax.yaxis)
    ax.set_xlabel("error: max-norm of u, omega, theta vs reference,\nrelative to each series' peak")
    ax.grid(True, which="major", alpha=0.4)
    ax.grid(True, which="minor", alpha=0.12)
    ax.legend(fontsize=7.5, loc="best", frameon=False)


def plot_case(path, name, case, rows, env) -> None:
    """Two panels sharing the error axis: the cost of one solve (left) and of a scene in a batch (right)."""
    from ..core.display import pyplot

    plt = pyplot()
    fig, (left, right) = plt.subplots(1, 2, figsize=(12.0, 6.2), dpi=100, layout="constrained", sharex=True)
    floor = ROUND_OFF / 3
    meta = case["meta"]
    _draw(left, [r for r in rows if not is_batch_cost(r["method"])], floor)
    _draw(right, [r for r in rows if is_batch_cost(r["method"])], floor)
    left.set_ylabel("median CPU time per call [s] (bar: fastest to slowest repeat)")
    left.set_title("one solve per call (what a fit pays per evaluation)", fontsize=10)
    right.set_ylabel(f"median CPU time per scene [s], batch of {meta['batch_size']} different scenes")
    right.set_title("batch throughput" + (f" ({meta['batch_engine']} engine)" if meta.get("batch_engine") else ""),
                    fontsize=10)
    fig.suptitle(case["title"], fontsize=11)
    rt = [r["rtol"] for r in rows if r["rtol"]]
    note = (f"numbers at points: log10 rtol ({min(rt):.0e}..{max(rt):.0e}, atol = rtol on the scaled problem); "
            f"reference: {meta['reference']}" + (f" (Radau {CHECK_RTOL:g} differs by {meta['reference_check']:.1e})"
                                                 if meta["reference_check"] else "")
            + "; scipy (plain): solve_ivp on a plain Python right-hand side, what a user writes without frictionlab"
            + f"\n{env['cpu']}, {env['cores']} cores; numpy {env['versions'].get('numpy')}, scipy "
              f"{env['versions'].get('scipy')}; errors below {ROUND_OFF:g} drawn at the dashed line (exact to round-off)")
    fig.text(0.0, 0.0, note, fontsize=7, color="#444444", va="bottom")
    fig.get_layout_engine().set(rect=(0, 0.06, 1, 0.94))
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
             "that series' peak; 'exact' and 'batch:*' times are per scene in a batch of different scenes (throughput, "
             f"drawn on their own axes); '{SINGLE_EXACT}' and the other methods per call; "
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

    from ..core.outfolder import atomic_dir

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
            from ..inference.cost import tolerance as fitcost

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
