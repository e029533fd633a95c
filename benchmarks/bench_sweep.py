"""A sweep larger than memory: peak resident memory of the client for a 1e6-scene sweep at the default samples.

    python benchmarks/bench_sweep.py [--scenes 1000000] [--chunk 5000] [--fields omega] [--out DIR]

The wear law on the paper's impact (golf ball, half-sine area, spin), u0, peak area and lambda varied per
scene (seeded), 201 samples per scene (simulate_sweep's default), closed form. Each configuration runs in
a fresh process, which reports its peak resident set size (getrusage ru_maxrss) and its wall and CPU time:
  streamed   simulate_sweep(..., out=DIR, fields=FIELDS, reduce=final spin and peak force): chunks written to
             Parquet and reduced where they run; only per-scene arrays come back
  in memory  simulate_sweep(...) returning every sample (the only way before), at --memory-scenes and half
             as many scenes: its peak grows linearly with the scenes, extrapolated from the two
Target: the 1e6-scene streamed sweep at most 2 GiB peak RSS.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile

CHILD = """
import json, resource, sys, time
import numpy as np
sys.path.insert(0, {bench!r})
from bench_sweep import family, ends
from frictionlab.solve.sweep import simulate_sweep
w0, c0 = time.perf_counter(), time.process_time()
batch, p = family({n})
if {streamed}:
    sw = simulate_sweep("wear", batch, p, solver="exact", chunk={chunk}, out={out!r}, fields={fields!r}, reduce=ends)
    check = float(np.nanmean(sw.scenes["final_spin"]))
else:
    r = simulate_sweep("wear", batch, p, solver="exact", chunk={chunk})
    check = float(np.nanmean(r.omega[:, -1]))
rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
print(json.dumps({{"rss": rss, "wall": time.perf_counter() - w0, "cpu": time.process_time() - c0, "check": check}}))
"""


def family(n, seed=11):
    """n impacts of the paper's kind (wear law), SceneBatch and per-scene parameters."""
    import numpy as np

    from frictionlab.physics.scene import HalfSineArea, Scene
    from frictionlab.solve.batch import SceneBatch

    rng = np.random.default_rng(seed)
    template = Scene(kind="impact", mass=0.046, u0=12.0, duration=500e-6, radius=0.0213,
                     area=HalfSineArea(130e-6, 500e-6), effects=frozenset({"spin"}))
    batch = SceneBatch.sweep(template, {"u0": rng.uniform(8, 30, n), "area.peak": rng.uniform(100e-6, 300e-6, n)})
    return batch, {"lam": rng.uniform(0.5e6, 2e6, n)}


def ends(r):
    """Final spin [rad/s] and peak force [N] per scene."""
    return {"final_spin": r.omega[:, -1], "peak_force": r.force.max(axis=1)}


def run(n, streamed, chunk, out, fields):
    bench = os.path.dirname(os.path.abspath(__file__))
    code = CHILD.format(bench=bench, n=n, streamed=streamed, chunk=chunk, out=out, fields=fields)
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    if res.returncode:
        raise SystemExit(res.stderr)
    return json.loads(res.stdout.strip().splitlines()[-1])


def du(path) -> int:
    return sum(os.path.getsize(os.path.join(d, f)) for d, _, fs in os.walk(path) for f in fs)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", type=int, default=1_000_000)
    ap.add_argument("--memory-scenes", type=int, default=50_000)
    ap.add_argument("--chunk", type=int, default=5000)
    ap.add_argument("--fields", nargs="+", default=["omega"])
    ap.add_argument("--out", default=None, help="folder for the Parquet output (default: a temporary one, removed)")
    args = ap.parse_args(argv)
    GiB = 2.0**30
    print(f"wear law, paper's impact varied, 201 samples per scene, closed form, chunks of {args.chunk}; "
          f"load average {', '.join(f'{x:.1f}' for x in os.getloadavg())}")
    half = run(args.memory_scenes // 2, False, args.chunk, None, None)
    r = run(args.memory_scenes, False, args.chunk, None, None)
    slope = (r["rss"] - half["rss"]) / (args.memory_scenes - args.memory_scenes // 2)
    print(f"  in memory: peak RSS {half['rss'] / GiB:.2f} GiB at {args.memory_scenes // 2} scenes, {r['rss'] / GiB:.2f} GiB "
          f"at {args.memory_scenes} ({r['wall']:.1f} s wall, {r['cpu']:.1f} s CPU): {slope / 1024:.1f} KiB a scene, "
          f"so about {(r['rss'] + slope * (args.scenes - args.memory_scenes)) / GiB:.0f} GiB at {args.scenes} scenes")
    tmp = tempfile.mkdtemp(prefix="bench_sweep.")
    out = args.out or os.path.join(tmp, "sweep")
    try:
        r = run(args.scenes, True, args.chunk, out, args.fields)
        size = du(out)
        print(f"  streamed, {args.scenes} scenes ({', '.join(args.fields)} per sample, final spin and peak force per "
              f"scene): peak RSS {r['rss'] / GiB:.2f} GiB, {r['wall']:.1f} s wall, {r['cpu']:.1f} s CPU, "
              f"{size / GiB:.2f} GiB of Parquet")
        print(f"RESULT peak RSS {r['rss'] / GiB:.2f} GiB (target <= 2 GiB: {'met' if r['rss'] <= 2 * GiB else 'NOT met'})")
    finally:
        if not args.out:
            shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
