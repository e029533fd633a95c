"""CPU of the area-rate fits on the four impact-outcome sets, the slowest fits of the default compare.

    python benchmarks/bench_outcome_fits.py [DATASET ...]

Each fit runs in this process after the imports (``fit("area-rate", [dataset])``, the comparison's
defaults); prints its CPU seconds (process time around the call, and the fit's own ``cpu_time``), its
number of model evaluations, status and fitted values with standard errors (None: not determined).
With eta' > 0 most rolling impacts stick, break away and slide again before the contact ends; the
batch engine's closed forms finish those phases vectorized (``batchexact.exact_phases``).
"""
import sys
import time

from frictionlab.inference.fitting.fit import fit
from frictionlab.io.dataset import load_dataset

DEFAULT = ["impact-outcome-synthetic", "kharaz2001-spin", "kharaz2001-tangential-cor", "kharaz2001-contact-angle"]


def main(names):
    total = own = 0.0
    for name in names or DEFAULT:
        ds = load_dataset(name)
        t0 = time.process_time()
        r = fit("area-rate", [ds])
        cpu = time.process_time() - t0
        total, own = total + cpu, own + r.cpu_time
        vals = {k: (f"{v.value:.10g}", None if v.stderr is None else f"{v.stderr:.3g}") for k, v in r.params.items()}
        print(f"{name:28s} {cpu:6.2f} CPU s (fit cpu_time {r.cpu_time:.2f}, nfev {r.nfev})  {r.status}  {vals}", flush=True)
    print(f"total {total:.2f} CPU s (the first includes lazy imports); fits' own cpu_time {own:.2f} s")


if __name__ == "__main__":
    main(sys.argv[1:])
