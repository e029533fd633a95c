"""The numbers behind tests/test_memory_laws.py, printed: steady state after a velocity step, aging-law
healing slope, Dahl loop area, LuGre vs Stribeck, and the critical stiffness found by bisection.

Run: .venv/bin/python benchmarks/memory_checks.py   (about a minute; not a timing benchmark)
"""
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import test_memory_laws as T  # noqa: E402

import frictionlab as fl  # noqa: E402

RS, K_C = T.RS, T.K_C

for law in ("rate-state-aging", "rate-state-slip"):
    tr = fl.simulate(law, T.slider(5 * K_C, (0.0, 5.0), (1e-6, 1e-5), 30.0), RS, solver="ode", t=np.array([0, 4.99, 30.0]))
    errs = [tr.load[i] - (RS["mu0"] + (RS["a"] - RS["b"]) * math.log(V / T.V0)) for i, V in ((1, 1e-6), (2, 1e-5))]
    print(f"{law}: mu_ss error before / after the 1 -> 10 um/s step: {errs[0]:.2e}, {errs[1]:.2e}")

holds = np.array([3.0, 10.0, 30.0, 100.0])
for law in ("rate-state-aging", "rate-state-slip"):
    dmu = T._healing(law, holds)
    slope, _ = np.polyfit(np.log(holds), dmu, 1)
    print(f"{law}: peak healing d mu = {np.round(dmu, 5).tolist()} after holds {holds.tolist()} s; "
          f"slope {slope:.5f} per e-fold = {slope * math.log(10):.5f} per decade (b = {RS['b']})")

lo, hi = 0.85 * K_C, 1.2 * K_C
for _ in range(6):
    mid = 0.5 * (lo + hi)
    lo, hi = (lo, mid) if T._growth(mid) < 1.0 else (mid, hi)
print(f"critical stiffness: bisection {0.5 * (lo + hi):.2f} /m (bracket {lo:.2f}-{hi:.2f}); "
      f"(b - a)/Dc = {K_C:.2f} /m")
