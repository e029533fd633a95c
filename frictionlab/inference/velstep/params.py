"""A nonlinear parameter of the velocity-step fit (``velstep.fit``) and the variable x the optimizer sees for it.

* 'lin': x = value / scale (a and b: scale AB_SCALE, their typical size; Nagata's c: its law's scale);
* 'log': x = ln(value) (Dc, the machine stiffness k);
* 'softplus': value = scale ln(1 + e^x), linear (value / scale) above scale and logarithmic below: b where its law
  keeps it above 0 (Nagata's, whose rate holds c / b). There the model's sensitivity to b grows as 1 / b at small b,
  and a fit whose b runs to its lower bound follows b and Dc down together (b / Dc fixed): a straight valley in
  (ln b, ln Dc), a curved one in (b, ln Dc), which Levenberg-Marquardt descends in hundreds of short steps. Above
  the knee B_KNEE, b is seen as a is (b - a is the well-determined combination there).
"""
from __future__ import annotations

import math

import attrs
import numpy as np

#: Optimizer scale of a and b (the laws' typical size).
AB_SCALE = 0.01
#: The knee of a 'softplus' b: below it the optimizer sees ln b (a tenth of b's typical size).
B_KNEE = 1e-3


@attrs.frozen
class Param:
    """A nonlinear parameter in laboratory units (um): its start, bounds, and the optimizer's x (module docstring)."""

    name: str  # display name ('a', 'Dc', 'spring.stiffness' or 'spring.stiffness[NAME]')
    key: str  # 'a', 'b', 'Dc', 'k' or an extra law parameter ('c')
    target: int  # the dataset of a stiffness, -1 for a shared law parameter
    transform: str  # 'lin' | 'log' | 'softplus'
    value: float  # start, laboratory units
    lower: float
    upper: float
    vary: bool
    fixed_by: str = ""
    scale: float = AB_SCALE  # of a 'lin' or 'softplus' parameter

    def to_x(self, v: float) -> float:
        if self.transform == "lin":
            return v / self.scale
        if self.transform == "log":
            return math.log(v)
        u = v / self.scale
        return u + math.log(-math.expm1(-u))  # ln(e^u - 1)

    def from_x(self, x: float) -> float:
        """The value at x, within the bounds (not a rounding error outside them)."""
        if self.transform == "lin":
            v = x * self.scale
        elif self.transform == "log":
            v = math.exp(x)
        else:
            v = self.scale * float(np.logaddexp(0.0, x))
        return min(max(v, self.lower), self.upper)

    def slope(self, x: float) -> float:
        """d value / d x at x."""
        return self.slope_at(self.from_x(x))

    def slope_at(self, v: float) -> float:
        """d value / d x at the value v."""
        if self.transform == "lin":
            return self.scale
        return v if self.transform == "log" else -self.scale * math.expm1(-v / self.scale)

    @property
    def bounds_x(self) -> tuple[float, float]:
        return self.to_x(self.lower), self.to_x(self.upper)


def with_value(x, i: int, xi: float) -> np.ndarray:
    """A copy of the optimizer's vector x with x[i] = xi."""
    out = np.array(x, dtype=float)
    out[i] = xi
    return out
