"""Contact-area models A(t) [m^2] and dA/dt [m^2/s], and reading them from ``[scene.area]``."""
from __future__ import annotations

import math

import attrs
import numpy as np

from ..core.errors import SceneError
from .sceneread import column_of, model_of, nonnegative, positive

@attrs.frozen
class HalfSineArea:
    """A(t) = peak sin(pi t / contact_time) for 0 <= t <= contact_time, else 0. Eq (1) of the paper."""

    peak: float = attrs.field(validator=nonnegative)  # [m^2]
    contact_time: float = attrs.field(validator=positive)  # [s]

    def __call__(self, t, x=None, speed=None):
        t = np.asarray(t, dtype=float)
        phi = math.pi / self.contact_time
        inside = (t >= 0) & (t <= self.contact_time)
        x = phi * t
        return np.where(inside, self.peak * np.sin(x), 0.0), np.where(inside, self.peak * phi * np.cos(x), 0.0)

    def value(self, t):
        """A(t) alone [m^2], bitwise the first of ``__call__``: a law that needs no dA/dt skips the cosine."""
        t = np.asarray(t, dtype=float)
        inside = (t >= 0) & (t <= self.contact_time)
        return np.where(inside, self.peak * np.sin(math.pi / self.contact_time * t), 0.0)


@attrs.frozen
class ConstantArea:
    """A constant contact area [m^2]."""

    area: float = attrs.field(validator=nonnegative)

    def __call__(self, t, x=None, speed=None):
        t = np.asarray(t, dtype=float)
        return np.full(t.shape, self.area), np.zeros(t.shape)


@attrs.frozen
class GrowthArea:
    """Wear growth with sliding length x: A = initial + rate * x [m^2, m^2/m]; dA/dt = rate * |slip|."""

    initial: float = attrs.field(validator=nonnegative)
    rate: float = attrs.field(validator=nonnegative)

    def __call__(self, t, x=None, speed=None):
        x = np.zeros(np.shape(t)) if x is None else np.asarray(x, dtype=float)
        speed = np.zeros(np.shape(t)) if speed is None else np.abs(speed)
        return self.initial + self.rate * x, self.rate * speed


@attrs.frozen(eq=False)
class TableArea:
    """A measured area column [m^2] at times t [s], smoothed by a spline whose derivative gives dA/dt.

    The smoothing spline's roughness penalty is chosen by generalized cross-validation on the
    data scaled to order one (time to [0, 1], area to its peak): in SI units (1e-4 s, 1e-4 m^2)
    the criterion is ill-posed and scipy returns a nearly straight line. Outside the measured
    span the area holds its end value and dA/dt is zero.
    """

    t: np.ndarray
    A: np.ndarray
    spline: object = attrs.field(init=False, repr=False)
    slope: object = attrs.field(init=False, repr=False)

    def __attrs_post_init__(self):
        from scipy.interpolate import make_smoothing_spline

        t, A = np.asarray(self.t, dtype=float), np.asarray(self.A, dtype=float)
        if t.ndim != 1 or t.shape != A.shape or t.size < 5:
            raise SceneError(f"area column: need at least 5 (t, A) samples of equal length, got {t.size} and {A.size}")
        if np.any(np.diff(t) <= 0) or not (np.all(np.isfinite(t)) and np.all(np.isfinite(A))):
            raise SceneError("area column: times must increase strictly and values be finite")
        if np.any(A < 0):
            raise SceneError("area column: negative contact area")
        span = t[-1] - t[0]
        peak = float(np.max(A)) or 1.0
        unit = make_smoothing_spline((t - t[0]) / span, A / peak)
        object.__setattr__(self, "spline", lambda tt: peak * unit((tt - t[0]) / span))
        slope = unit.derivative()
        object.__setattr__(self, "slope", lambda tt: (peak / span) * slope((tt - t[0]) / span))

    def __call__(self, t, x=None, speed=None):
        t = np.asarray(t, dtype=float)
        inside = (t >= self.t[0]) & (t <= self.t[-1])
        tc = np.clip(t, self.t[0], self.t[-1])
        return np.maximum(self.spline(tc), 0.0), np.where(inside, self.slope(tc), 0.0)


#: Keys each area and normal-force model reads; anything else is a typo that would be ignored.
AREA_KEYS = {"half-sine": {"peak", "contact_time"}, "constant": {"area"}, "growth": {"initial", "rate"},
             "column": {"column"}}


def area_from_spec(a, where, q, columns, t):
    if a is None:
        return None
    p = "scene.area"
    model = model_of(a, AREA_KEYS, where, p)
    if model == "half-sine":
        return HalfSineArea(q("peak", "m^2", a, p), q("contact_time", "s", a, p))
    if model == "constant":
        return ConstantArea(q("area", "m^2", a, p))
    if model == "growth":
        rate = q("rate", "m^2/m", a, p, positive=False)
        if rate < 0:
            raise SceneError(f"{where}: {p}.rate must be >= 0 (the contact grows as it slides), got {a['rate']!r}")
        return GrowthArea(q("initial", "m^2", a, p), rate)
    if model == "column":
        A = column_of(columns, a.get("column", "A"), where, p, "A")
        if np.any(A < 0):
            raise SceneError(f"{where}: area column has negative values")
        try:
            return TableArea(t, A)
        except SceneError as exc:
            raise SceneError(f"{where}: {p}: {exc}") from None
    raise SceneError(f"{where}: {p}.model must be one of half-sine, constant, growth, column; got {model!r}")

