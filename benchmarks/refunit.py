"""The reference unit of the speed benchmarks: 1000 plain solve_ivp DOP853 solves of the paper's dimensionless
wear impact at rtol = atol = 1e-8.

The paper's impact (Arakawa, Sci. Rep. 2017: m du/dt = -lam A0 sin(phi t) u, I domega/dt = r lam A0 sin(phi t) u)
in the time s = phi t in [0, pi] and the velocities U = u / u0, W = omega r / u0:
    dU/ds = -b sin(s) U,   dW/ds = (5/2) b sin(s) U,   dTheta/ds = W,   b = lam A0 / (m phi) = 0.81,
from U = 1, W = Theta = 0, with 51 outputs: what a user writes with scipy alone (a plain Python right-hand
side). ``unit()`` returns the CPU seconds of n such solves (the median of five blocks of n / 5, times five);
a benchmark takes it right before and right after what it measures, and divides by the mean of the two (on a
shared or virtual machine the CPU's speed drifts over minutes, so only ratios taken in one spell compare).
"""
from __future__ import annotations

import math
import os
import time

B = 0.81  # the paper's b at 28 m/s


def unit(n: int = 1000, blocks: int = 5) -> float:
    """CPU seconds of n plain solve_ivp DOP853 solves of the dimensionless wear impact (rtol = atol = 1e-8): the
    median of ``blocks`` blocks of n / blocks solves, times ``blocks``. On a shared virtual machine one block now
    and then takes up to twice the others (another process, the host); the median leaves such a block out, where
    one timing of all n would count it (which makes the unit larger and a ratio to it smaller)."""
    import numpy as np
    from scipy.integrate import solve_ivp

    s_eval = np.linspace(0.0, math.pi, 51)

    def rhs(s, y):
        U, W, _ = y
        f = B * math.sin(s) * U
        return [-f, 2.5 * f, W]

    def one():
        return solve_ivp(rhs, (0.0, math.pi), [1.0, 0.0, 0.0], method="DOP853", t_eval=s_eval, rtol=1e-8, atol=1e-8)

    one()  # warm up
    times = []
    for _ in range(blocks):
        t0 = time.process_time()
        for _ in range(max(1, n // blocks)):
            sol = one()
        times.append(time.process_time() - t0)
    cpu = sorted(times)[len(times) // 2] * blocks
    exact = 2.5 * (1.0 - math.exp(-2.0 * B))  # U = exp(b (cos s - 1)), W = (5/2)(1 - U): at s = pi
    if abs(sol.y[1, -1] - exact) > 1e-6:
        raise SystemExit(f"reference solve is off: {sol.y[1, -1]} vs {exact}")
    return cpu


def load() -> str:
    """The machine's load, for the record."""
    one, five, fifteen = os.getloadavg()
    return f"load average {one:.2f}, {five:.2f}, {fifteen:.2f} (1, 5, 15 min) on {os.cpu_count()} CPUs"


if __name__ == "__main__":
    print(f"unit: {unit():.3f} CPU s for 1000 solves; {load()}")
