"""Normal-force models N(t) [N], and reading them from ``[scene.normal]``."""
from __future__ import annotations

import math

import attrs
import numpy as np

from ..core.errors import SceneError
from .sceneread import column_of, model_of, nonnegative, positive

G = 9.80665  # standard gravity [m/s^2]

@attrs.frozen
class HalfSineNormal:
    """N(t) = peak sin(pi t / contact_time), impulse = 2 peak contact_time / pi = m v_n (1 + e)."""

    impulse: float = attrs.field(validator=nonnegative)  # [N s]
    contact_time: float = attrs.field(validator=positive)  # [s]

    @property
    def peak(self) -> float:
        return self.impulse * math.pi / (2.0 * self.contact_time)

    def __call__(self, t, A=None):
        t = np.asarray(t, dtype=float)
        phi = math.pi / self.contact_time
        inside = (t >= 0) & (t <= self.contact_time)
        return np.where(inside, self.peak * np.sin(phi * t), 0.0)


@attrs.frozen
class HertzNormal:
    """Hertz-type N = coefficient * A^(3/2) [N/m^3]; for a sphere k = 4 E* / (3 pi^1.5 R)."""

    coefficient: float = attrs.field(validator=nonnegative)

    def __call__(self, t, A=None):
        return self.coefficient * np.maximum(A, 0.0) ** 1.5


@attrs.frozen(eq=False)
class TableNormal:
    """A measured normal-force column, linearly interpolated [N]."""

    t: np.ndarray
    N: np.ndarray

    def __call__(self, t, A=None):
        return np.interp(t, self.t, self.N)


@attrs.frozen
class ConstantNormal:
    """A constant normal force [N] (a spring-slider's normal load)."""

    value: float = attrs.field(validator=positive)

    def __call__(self, t, A=None):
        return np.full(np.shape(t), self.value)


@attrs.frozen
class WeightNormal:
    """N = m g cos(alpha) on an incline [N]."""

    value: float = attrs.field(validator=nonnegative)

    def __call__(self, t, A=None):
        return np.full(np.shape(t), self.value)


#: Keys each normal-force model reads; anything else is a typo that would be ignored.
NORMAL_KEYS = {"half-sine": {"contact_time", "impulse", "normal_speed", "restitution"}, "constant": {"value"},
               "hertz": {"coefficient", "modulus", "radius"}, "column": {"column"}, "weight": set()}


def normal_from_spec(n, where, q, columns, t, mass, contact_time, spec, incline):
    if n is None:
        return None
    p = "scene.normal"
    model = model_of(n, NORMAL_KEYS, where, p)
    if model == "half-sine":
        tc = q("contact_time", "s", n, p, required=contact_time is None, default=contact_time)
        if "impulse" in n:
            impulse = q("impulse", "N*s", n, p)
        else:
            vn = q("normal_speed", "m/s", n, p)
            e = q("restitution", "", n, p, positive=False)
            if not 0 <= e <= 1:
                raise SceneError(f"{where}: {p}.restitution must be in [0, 1], got {e}")
            impulse = mass * vn * (1 + e)
        return HalfSineNormal(impulse, tc)
    if model == "hertz":
        if "coefficient" in n:
            return HertzNormal(q("coefficient", "N/m^3", n, p))
        modulus = q("modulus", "Pa", n, p)
        radius = q("radius", "m", n, p)
        return HertzNormal(4.0 * modulus / (3.0 * math.pi**1.5 * radius))
    if model == "column":
        return TableNormal(t, column_of(columns, n.get("column", "N"), where, p, "N"))
    if model == "constant":
        return ConstantNormal(q("value", "N", n, p))
    if model == "weight":
        if incline is None:
            raise SceneError(f"{where}: {p}.model = 'weight' needs scene.incline")
        return WeightNormal(mass * G * math.cos(incline))
    raise SceneError(f"{where}: {p}.model must be one of half-sine, hertz, column, weight, constant; got {model!r}")

