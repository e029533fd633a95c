"""Memory of the velocity-step fit against the number of samples: peak resident memory of one fit, each size in a
process of its own, and the slope in bytes per sample.

    python benchmarks/memory_velstep.py [--sizes 6000 60000 600000] [--law rate-state-aging]

Each process builds a synthetic velocity step (3 -> 10 um/s at 20 s of a 50 s record, aging law, a trend, AR(1)
noise of coefficient 0.6 per sample; the sampling rate set by the size), declared measured-like (trend and stiffness
fitted, ``correlation = "ar1"``), in memory; it then resets the kernel's peak counter (Linux: /proc/self/clear_refs)
and fits. Printed per size: resident memory before the fit, the fit's peak, the fit's CPU time; then the least-
squares slope of the peak over the size (bytes per sample), and of the fit's own increase (peak - before). The
target: at most 1 KB a sample beyond the data (600,000 samples under 2 GB, 3.6 million under 8 GB).
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def _status(key: str) -> int:
    """A field of /proc/self/status in bytes (VmRSS, VmHWM)."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(key + ":"):
            return int(line.split()[1]) * 1024
    raise KeyError(key)


def child(n: int, law: str) -> None:
    import attrs

    import frictionlab as fl
    from frictionlab.inference.noise.ar1 import draw
    from frictionlab.inference.fitting.predict import Target
    from frictionlab.io.noise import estimate

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from calibration_ar1 import make_dataset

    duration, ts, v1, v2 = 50.0, 20.0, 3.0, 10.0
    with tempfile.TemporaryDirectory() as tmp:
        template, _ = make_dataset(Path(tmp), "ar1", quick=True)
    t = np.linspace(0.0, duration, n, endpoint=False)
    x = np.where(t < ts, v1 * t, v1 * ts + v2 * (t - ts))
    scene = attrs.evolve(template.scene, spring=attrs.evolve(template.scene.spring, times=(0.0, ts)))
    truth = {"mu0": 0.6, "a": 0.009, "b": 0.0095, "Dc": 7e-6}
    curve = fl.simulate(law, scene, truth, solver="ode", t=t).load + 3e-6 * (x - v1 * ts)
    y = curve + draw(np.random.default_rng(1), np.full(n, 8e-4), np.r_[0.0, np.full(n - 1, 0.6)])
    cols = {"t": t, "x": x * 1e-6, "mu": y}
    est = estimate(cols, "mu")
    data = attrs.evolve(template, columns=cols, scene=scene, noise={"mu": est.sigma}, noise_kind="estimated",
                        noise_est={"mu": est}, noise_df={"mu": est.df}, noise_correlation="ar1")
    target = Target(data, "mu", y, np.full(n, est.sigma))
    del curve, est
    before = _status("VmRSS")
    Path("/proc/self/clear_refs").write_text("5")  # the peak (VmHWM) counts from here
    c0 = time.process_time()
    f = fl.fit(law, target, trend=True, stiffness=True)
    cpu = time.process_time() - c0
    print(n, before, _status("VmHWM"), f"{cpu:.1f}", f.status)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[6000, 60000, 600000])
    ap.add_argument("--law", default="rate-state-aging")
    ap.add_argument("--child", type=int, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        child(args.child, args.law)
        return 0
    rows = []
    print(f"{'samples':>9} {'before fit MB':>14} {'fit peak MB':>12} {'fit CPU s':>10}  status")
    for n in args.sizes:
        out = subprocess.run([sys.executable, __file__, "--child", str(n), "--law", args.law], capture_output=True,
                             text=True)
        if out.returncode:
            print(f"{n:>9} failed: {out.stderr.strip().splitlines()[-1] if out.stderr.strip() else out.returncode}")
            continue
        size, before, peak, cpu, status = out.stdout.split()
        rows.append((int(size), int(before), int(peak)))
        print(f"{int(size):>9} {int(before) / 2**20:>14.1f} {int(peak) / 2**20:>12.1f} {float(cpu):>10.1f}  {status}")
    if len(rows) >= 2:
        n, before, peak = (np.array(c, dtype=float) for c in zip(*rows))
        slope = np.polyfit(n, peak, 1)[0]
        own = np.polyfit(n, peak - before, 1)[0]
        print(f"slope of the fit's peak: {slope:.0f} bytes a sample; of the fit's increase over the data in memory: "
              f"{own:.0f} bytes a sample (target: at most 1024)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
