"""The dimensionless elastic Hertz impact y'' = -(5/4) y^(3/2), y(0) = 0, y'(0) = 1, tabulated once.

scipy's ``solve_ivp`` (DOP853, rtol 1e-13) integrates it to the end of contact s_end = (4/5) B(2/5, 1/2) = 2.9432;
its public dense output gives y and y' on KNOTS equal steps of [0, s_end], and the ODE itself y''. Between knots, y
is the cubic Hermite interpolant of (y, y') and y' that of (y', y''): C1 in both, within 1e-13 (y) and 1e-10 (y')
of the dense solution (tests/test_outcome.py), and on floats a few microseconds a call, which an impact's
right-hand side makes at every stage."""
from __future__ import annotations

import functools
import math

import numpy as np

#: Equal steps of the tabulated contact (the Hermite interpolants' error falls as the fourth power of the step).
KNOTS = 4096


@functools.cache
def solution():
    """(s_end, OdeSolution) of the dimensionless Hertz impact: OdeSolution(s) -> rows y, y'."""
    from scipy.integrate import solve_ivp

    def rhs(s, z):
        return [z[1], -1.25 * max(z[0], 0.0) ** 1.5]

    def end(s, z):
        return z[0]

    end.terminal, end.direction = True, -1
    sol = solve_ivp(rhs, (0.0, 4.0), [0.0, 1.0], method="DOP853", rtol=1e-13, atol=1e-15, dense_output=True,
                    events=end)
    return float(sol.t_events[0][0]), sol.sol


@functools.cache
def table() -> tuple[float, float, list, np.ndarray]:
    """(s_end, step, rows (y, y', y'') at each knot as floats, the same as a (KNOTS + 1, 3) array)."""
    s_end, dense = solution()
    s = np.linspace(0.0, s_end, KNOTS + 1)
    y, dy = dense(s)
    y = np.maximum(y, 0.0)
    y[-1] = 0.0
    rows = np.column_stack([y, dy, -1.25 * y ** 1.5])
    return s_end, s_end / KNOTS, [tuple(r) for r in rows.tolist()], rows


def at(s: float) -> tuple[float, float]:
    """(y, y') at one s in [0, s_end]."""
    _, h, rows, _ = table()
    u = s / h
    k = min(int(u), KNOTS - 1)
    x = u - k
    (y0, d0, c0), (y1, d1, c1) = rows[k], rows[k + 1]
    w = 1.0 - x
    h00, h01 = (1.0 + 2.0 * x) * w * w, x * x * (3.0 - 2.0 * x)
    h10, h11 = x * w * w * h, -x * x * w * h
    return h00 * y0 + h10 * d0 + h01 * y1 + h11 * d1, h00 * d0 + h10 * c0 + h01 * d1 + h11 * c1


def many(s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(y, y') at every s of an array (any shape) in [0, s_end]."""
    _, h, _, rows = table()
    u = np.asarray(s, dtype=float) / h
    k = np.minimum(np.where(u > 0, u, 0.0).astype(int), KNOTS - 1)  # (NaN: knot 0)
    x = u - k
    w = 1.0 - x
    h00, h01 = (1.0 + 2.0 * x) * w * w, x * x * (3.0 - 2.0 * x)
    h10, h11 = x * w * w * h, -x * x * w * h
    a, b = rows[k], rows[k + 1]
    return (h00 * a[..., 0] + h10 * a[..., 1] + h01 * b[..., 0] + h11 * b[..., 1],
            h00 * a[..., 1] + h10 * a[..., 2] + h01 * b[..., 1] + h11 * b[..., 2])


def end() -> float:
    """s_end, the dimensionless end of contact."""
    return table()[0]


def exact_end() -> float:
    """(4/5) B(2/5, 1/2): s_end in closed form, to check the tabulated one."""
    return 0.8 * math.gamma(0.4) * math.gamma(0.5) / math.gamma(0.9)
