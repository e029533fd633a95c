"""How long the default comparison takes, where the time goes, and what that is worth in plain solve_ivp solves.

    python benchmarks/bench_compare.py [--repeat R] [--jobs J] [--keep DIR]

Runs README command 1 as a user does: ``frictionlab compare --out DIR --force`` in a fresh process (every
default law on every built-in dataset, the equivalence tests, the bootstrap, the report written), through
``stage_cpu.py``, which counts the process's CPU time by part. Its first output is where the CPU went: the
start-up imports, each stage, the report's figures (by kind) and the rest, with the measured records' share
(their fits and the figures named after them); then each stage's wall time as ``results.json`` records it (fits,
rank, equivalence, transfer, bootstrap, answer; with ``--jobs 1`` wall time is CPU time), the report and
start-up (the rest of the process's wall time), and the share of the fits on measured datasets (the
records). Then the run's wall and CPU time (the process and its workers, user + system), the slowest fits, and

    ratio = CPU of compare / the unit

where the unit is ``refunit.unit()``: the CPU time of 1000 plain ``solve_ivp`` DOP853 solves of the paper's
dimensionless wear impact at rtol = atol = 1e-8 (what a user writes without this library), measured right
before and right after each compare run; a run's ratio uses the mean of the two (on a shared or virtual
machine the CPU's speed drifts by tens of percent over minutes). Target: at most 12. The machine's load is
printed: CPU time is the measure to trust on a shared machine.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import refunit


def children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_compare(out: Path, jobs: int | None = None) -> dict:
    """One ``frictionlab compare`` in a fresh process (``stage_cpu.py``: the command line, its CPU counted by part)."""
    fd, name = tempfile.mkstemp(suffix=".json", prefix="cpu-parts-")
    os.close(fd)
    parts_file = Path(name)
    c0, w0 = children_cpu(), time.perf_counter()
    subprocess.run([sys.executable, str(Path(__file__).with_name("stage_cpu.py")), str(parts_file), "compare", "--out",
                    str(out), "--force"] + (["--jobs", str(jobs)] if jobs else []), check=True, stdout=subprocess.DEVNULL)
    wall, cpu = time.perf_counter() - w0, children_cpu() - c0
    res = json.loads((out / "results.json").read_text())
    parts = json.loads(parts_file.read_text())
    parts_file.unlink()
    return {"wall": wall, "cpu": cpu, "results": res, "parts": parts}


def cpu_parts(r: dict) -> dict:
    """CPU seconds of each part of one run (with --jobs 1 every part ran in the one process): imports, each
    stage, the figures, and the rest (reading the datasets, planning, the report's text)."""
    p = r["parts"]
    out = {"start-up imports": p["imports"]}
    out.update({f"stage {k}": v for k, v in p["stages"].items()})
    out["report figures"] = sum(p["figures"].values())
    out["datasets, planning, report text"] = p["total"] - sum(out.values())
    return out


def stages(r: dict) -> dict:
    """Wall seconds of each stage of one run, the report and start-up being the rest of the process's wall time."""
    res = r["results"]
    out = dict(res.get("timings_s", {}))
    out["report and start-up"] = r["wall"] - res["wall_time_s"]
    return out


def measured_share(res: dict, kinds=None) -> tuple[float, float]:
    """(CPU seconds of the fits on measured datasets (of the dataset ``kinds``; None: any), of all fits)."""
    mine = {d["name"] for d in res.get("datasets", []) if (d.get("provenance") or {}).get("kind") == "measured"
            and (kinds is None or d.get("kind") in kinds)}
    cpu = [(f.get("cpu_time_s") or 0.0, f["dataset"] in mine) for f in res["fits"]]
    return sum(c for c, m in cpu if m), sum(c for c, _ in cpu)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--keep", type=Path, help="write the (last) report here instead of a temporary folder")
    ap.add_argument("--jobs", type=int, help="compare's --jobs (default: its own); 1 makes each stage's wall time "
                                              "its CPU time, for finding where the CPU goes")
    args = ap.parse_args()
    runs = []
    for i in range(args.repeat):
        tmp = Path(tempfile.mkdtemp(prefix="bench-compare-"))
        out = args.keep if (args.keep and i == args.repeat - 1) else tmp / "report"
        before = refunit.unit()
        try:
            r = run_compare(out, args.jobs)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
        after = refunit.unit()
        r.update(before=before, after=after, unit=0.5 * (before + after), load=refunit.load())
        runs.append(r)
    print("where the CPU goes (CPU s of this process, user + system; with --jobs 1 that is all of it):")
    for k in dict.fromkeys(k for r in runs for k in cpu_parts(r)):
        vals = [cpu_parts(r).get(k, 0.0) for r in runs]
        total = statistics.median([r["parts"]["total"] for r in runs])
        print(f"  {k:34s} {statistics.median(vals):7.2f} s  ({100 * statistics.median(vals) / total:4.1f}%; runs: "
              f"{', '.join(f'{v:.2f}' for v in vals)})")
    last = runs[-1]["parts"]
    kinds = sorted(last["figures"], key=lambda k: -last["figures"][k])
    print("  figures by kind (last run): " + ", ".join(f"{k} {last['figures'][k]:.2f} s ({last['figure counts'][k]})"
                                                      for k in kinds))
    res = runs[-1]["results"]
    for what, kinds in (("the measured datasets", None), ("the measured velocity-step records", ("spring-slider",))):
        measured = [d["name"] for d in res.get("datasets", []) if (d.get("provenance") or {}).get("kind") == "measured"
                    and (kinds is None or d.get("kind") in kinds)]
        rec, _ = measured_share(res, kinds)
        figs = sum(v for name, v in last["figure by name"].items() if any(m in name for m in measured))
        print(f"  {what} ({', '.join(measured) or 'none'}): their fits {rec:.2f} CPU s and the figures named after "
              f"them {figs:.2f} s, {100 * (rec + figs) / last['total'] if last['total'] else 0:.1f}% of the run's CPU")
    print()
    print("where the time goes (wall s of each stage; with --jobs 1 on an idle machine wall is CPU):")
    names = list(dict.fromkeys(k for r in runs for k in stages(r)))
    for k in names:
        vals = [stages(r).get(k, 0.0) for r in runs]
        total = statistics.median([r["wall"] for r in runs])
        print(f"  {k:22s} {statistics.median(vals):7.2f} s  ({100 * statistics.median(vals) / total:4.1f}% of the wall "
              f"time; runs: {', '.join(f'{v:.2f}' for v in vals)})")
    rec, fits_cpu = measured_share(runs[-1]["results"])
    print(f"  fits on measured datasets: {rec:.2f} CPU s of the fits' {fits_cpu:.2f} "
          f"({100 * rec / fits_cpu if fits_cpu else 0:.1f}%)")
    print()
    for i, r in enumerate(runs):
        print(f"run {i + 1}: wall {r['wall']:6.1f} s, CPU {r['cpu']:6.1f} s (process and workers); unit {r['before']:.2f} CPU s "
              f"before, {r['after']:.2f} after ({r['unit']:.2f} ms a solve); CPU / unit = {r['cpu'] / r['unit']:5.1f}; {r['load']}")
    res = runs[-1]["results"]
    fits = res["fits"]
    ok = [f for f in fits if f["status"] == "ok"]
    print(f"\n{len(fits)} fits ({len(ok)} ok), {len(res.get('equivalence', []))} equivalence tests, "
          f"bootstrap {res['settings'].get('bootstrap')} resamples; jobs {res['settings'].get('jobs')}")
    print(f"CPU of the fits (sum): {fits_cpu:.1f} s; model evaluations {sum(f['nfev'] for f in fits)}")
    print("slowest fits (CPU s):")
    for f in sorted(ok, key=lambda f: -f.get("cpu_time_s", 0.0))[:6]:
        print(f"  {f.get('cpu_time_s', 0.0):6.2f} s  {f['nfev']:5d} evals  {f['law']} [{f['solver']}] on {f['dataset']}")
    ratios = [r["cpu"] / r["unit"] for r in runs]
    wall, cpu = statistics.median([r["wall"] for r in runs]), statistics.median([r["cpu"] for r in runs])
    print(f"\nmedian over {len(runs)} run(s): wall {wall:.1f} s, CPU {cpu:.1f} s, RATIO CPU / unit "
          f"{statistics.median(ratios):.1f} (runs {', '.join(f'{x:.1f}' for x in ratios)}; target <= 12: "
          f"{'met' if statistics.median(ratios) <= 12 else 'not met'})")
    v = res["versions"]
    print(f"{v.get('platform')}, {os.cpu_count()} CPUs; python {v.get('python')}, numpy {v.get('numpy')}, "
          f"scipy {v.get('scipy')}, lmfit {v.get('lmfit')}")


if __name__ == "__main__":
    main()
