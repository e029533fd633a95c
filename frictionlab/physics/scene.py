"""Scenes: a body, a contact history (area and normal-force models), a drive and named effects.

A scene is pure data in SI floats. It comes from a dataset's ``[scene]`` TOML table
(``Scene.from_spec``) or is built in Python. What to integrate is decided later by the
plan (``frictionlab.solve.plan``), from the scene's effects and the law's requirements.
"""
from __future__ import annotations

import math
from collections.abc import Mapping

import attrs
import numpy as np

from ..core.errors import SceneError
from ..core.units import to_si
from .contact import (
    Compliance,
    MindlinCompliance,
    compliance_from_spec,
    materials_from_spec,
)

G = 9.80665  # standard gravity [m/s^2]

KINDS = ("impact", "incline", "impact-outcome", "spring-slider")

#: Effects a scene may switch on in its ``effects`` list.
EFFECTS = {
    "spin": "integrate spin omega and rotation angle theta from the friction torque (needs radius)",
    "slip-coupling": "contact-point slip u = v - r omega (rigid sphere) instead of u = v",
    "compliance": ("tangential compliance at the contact (Maw, Barber and Fawcett 1976): [scene.compliance] "
                   "model = 'linear' (spring and damper), 'mindlin' (k_t = 8 G* a(t) from [scene.materials]) or "
                   "'mindlin-deresiewicz' (microslip and loading history, impact outcomes; frictionlab.physics.mdr)"),
    "gravity": "gravity along an incline, m g sin(alpha), with N = m g cos(alpha)",
}


# --- validation of Python-built models: no NaN or negative size slips through ----------
def _number(test, words):
    def check(instance, attribute, value):
        if isinstance(value, float) and math.isfinite(value) and test(value):  # the common case (float, np.float64)
            return
        # a batch view (frictionlab.solve.batch) puts arrays over scenes in these fields: check every element
        v = None if isinstance(value, (bool, np.bool_)) else np.asarray(value)
        ok = v is not None and v.dtype.kind in "fi"
        if not ok or not np.isfinite(v).all() or not np.asarray(test(v)).all():
            raise SceneError(f"{type(instance).__name__}.{attribute.name} must be {words}, got {value!r}")
    return check


_positive = _number(lambda v: v > 0, "a positive finite number")
_nonnegative = _number(lambda v: v >= 0, "a finite number >= 0")
_finite = _number(lambda v: True, "a finite number")


def _optional(check):
    def optional(instance, attribute, value):
        if value is not None:
            check(instance, attribute, value)
    return optional


# --- reading a [scene] table --------------------------------------------------------------
def spec_reader(spec: Mapping, where: str):
    """q(key, unit, table=spec, prefix='scene', required=True, positive=True, default=None) -> SI float.

    Reads a quantity string from a TOML table with one-line errors naming file and field.
    """
    def q(key, unit, table=spec, prefix="scene", required=True, positive=True, default=None):
        if key not in table:
            if required:
                raise SceneError(f"{where}: [{prefix}] is missing '{key}'")
            return default
        value = to_si(table[key], unit, f"{where}: {prefix}.{key}")
        if positive and not value > 0:
            raise SceneError(f"{where}: {prefix}.{key} must be positive, got {table[key]!r}")
        return value

    return q


def read_effects(spec: Mapping, where: str, default=()) -> frozenset:
    """The ``effects`` list of a [scene] table, checked against EFFECTS."""
    effects = spec.get("effects", list(default))
    if not isinstance(effects, list) or not all(isinstance(e, str) for e in effects):
        raise SceneError(f"{where}: scene.effects must be a list of names")
    bad = [e for e in effects if e not in EFFECTS]
    if bad:
        raise SceneError(f"{where}: scene.effects: unknown effect(s) {bad}; known: {', '.join(EFFECTS)}")
    return frozenset(effects)


# --- contact-area models ------------------------------------------------------------
@attrs.frozen
class HalfSineArea:
    """A(t) = peak sin(pi t / contact_time) for 0 <= t <= contact_time, else 0. Eq (1) of the paper."""

    peak: float = attrs.field(validator=_nonnegative)  # [m^2]
    contact_time: float = attrs.field(validator=_positive)  # [s]

    def __call__(self, t, x=None, speed=None):
        t = np.asarray(t, dtype=float)
        phi = math.pi / self.contact_time
        inside = (t >= 0) & (t <= self.contact_time)
        return np.where(inside, self.peak * np.sin(phi * t), 0.0), np.where(inside, self.peak * phi * np.cos(phi * t), 0.0)

    def value(self, t):
        """A(t) alone [m^2], bitwise the first of ``__call__``: a law that needs no dA/dt skips the cosine."""
        t = np.asarray(t, dtype=float)
        inside = (t >= 0) & (t <= self.contact_time)
        return np.where(inside, self.peak * np.sin(math.pi / self.contact_time * t), 0.0)


@attrs.frozen
class ConstantArea:
    """A constant contact area [m^2]."""

    area: float = attrs.field(validator=_nonnegative)

    def __call__(self, t, x=None, speed=None):
        t = np.asarray(t, dtype=float)
        return np.full(t.shape, self.area), np.zeros(t.shape)


@attrs.frozen
class GrowthArea:
    """Wear growth with sliding length x: A = initial + rate * x [m^2, m^2/m]; dA/dt = rate * |slip|."""

    initial: float = attrs.field(validator=_nonnegative)
    rate: float = attrs.field(validator=_nonnegative)

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


# --- normal-force models ------------------------------------------------------------
@attrs.frozen
class HalfSineNormal:
    """N(t) = peak sin(pi t / contact_time), impulse = 2 peak contact_time / pi = m v_n (1 + e)."""

    impulse: float = attrs.field(validator=_nonnegative)  # [N s]
    contact_time: float = attrs.field(validator=_positive)  # [s]

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

    coefficient: float = attrs.field(validator=_nonnegative)

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

    value: float = attrs.field(validator=_positive)

    def __call__(self, t, A=None):
        return np.full(np.shape(t), self.value)


@attrs.frozen
class WeightNormal:
    """N = m g cos(alpha) on an incline [N]."""

    value: float = attrs.field(validator=_nonnegative)

    def __call__(self, t, A=None):
        return np.full(np.shape(t), self.value)


@attrs.frozen(eq=False)
class SpringLoad:
    """A spring of stiffness k per unit normal force [1/m] pulled at a load-point velocity that steps.

    The load point moves at velocities[i] [m/s] from times[i] [s] on (times[0] = 0); a velocity of 0
    is a hold. The spring force per unit normal force, mu = K (x_lp - x) / N, obeys
    d mu/dt = k (V_lp - v): k = K / N is the stiffness per unit normal stress of the
    rate-and-state literature (k_c = (b - a) / Dc). The block is quasi-static (see plan.py).
    """

    stiffness: float = attrs.field(validator=_positive)
    times: tuple = attrs.field(converter=lambda x: tuple(float(v) for v in x))
    velocities: tuple = attrs.field(converter=lambda x: tuple(float(v) for v in x))

    def __attrs_post_init__(self):
        t, v = np.asarray(self.times), np.asarray(self.velocities)
        if t.size == 0 or t.size != v.size:
            raise SceneError(f"SpringLoad: times and velocities must be non-empty lists of one length, got {t.size} "
                             f"and {v.size}")
        if t[0] != 0.0 or np.any(np.diff(t) <= 0) or not np.all(np.isfinite(t)):
            raise SceneError(f"SpringLoad: times must start at 0 s and increase strictly, got {list(self.times)}")
        if not np.all(np.isfinite(v)) or np.any(v < 0):
            raise SceneError(f"SpringLoad: velocities must be finite and >= 0, got {list(self.velocities)}")

    def velocity(self, t):
        """Load-point velocity V_lp(t) [m/s]."""
        i = np.searchsorted(np.asarray(self.times), np.asarray(t, dtype=float), side="right") - 1
        return np.asarray(self.velocities)[np.clip(i, 0, len(self.times) - 1)]

    @property
    def breaks(self) -> tuple[float, ...]:
        """Times [s] at which the load-point velocity steps (where an integrator should restart)."""
        return self.times[1:]


@attrs.frozen
class Scene:
    """Everything about an experiment except the friction law; SI floats throughout."""

    kind: str
    mass: float = attrs.field(validator=_positive)  # [kg]
    u0: float = attrs.field(validator=_finite)  # initial slip at the contact [m/s] (body velocity minus r omega0 with slip coupling)
    duration: float = attrs.field(validator=_nonnegative)  # simulated time span [s]
    radius: float | None = attrs.field(default=None, validator=_optional(_positive))  # [m]
    inertia_factor: float = attrs.field(default=0.4, validator=_positive)  # I = inertia_factor * m r^2
    omega0: float = attrs.field(default=0.0, validator=_finite)  # [rad/s]
    incline: float | None = None  # [rad]
    area: object | None = None
    normal: object | None = None
    compliance: Compliance | MindlinCompliance | None = None
    effects: frozenset = attrs.field(default=frozenset(), converter=frozenset)
    spring: SpringLoad | None = None  # kind 'spring-slider': the driving spring and its load point

    def __attrs_post_init__(self):
        if self.kind not in KINDS:
            raise SceneError(f"Scene.kind must be one of {', '.join(KINDS)}, got {self.kind!r}")
        unknown = sorted(set(self.effects) - set(EFFECTS))
        if unknown:
            raise SceneError(f"Scene.effects: unknown effect(s) {unknown}; known: {', '.join(EFFECTS)}")
        if self.incline is not None:
            _finite(self, attrs.fields(Scene).incline, self.incline)
            if not np.all((0 < np.asarray(self.incline)) & (np.asarray(self.incline) < math.pi / 2)):
                raise SceneError(f"Scene.incline must be between 0 and pi/2 rad, got {self.incline!r}")
        if {"spin", "slip-coupling"} & set(self.effects) and self.radius is None:
            raise SceneError("Scene: effects 'spin' and 'slip-coupling' need a radius")
        if self.kind == "spring-slider" and (self.spring is None or self.normal is None):
            raise SceneError("a spring-slider scene needs a spring (SpringLoad) and a normal force model")
        if "gravity" in self.effects:
            if self.incline is None:
                raise SceneError("effect 'gravity' needs scene.incline")
            if self.normal is None:  # a block on an incline is pressed on by its weight
                object.__setattr__(self, "normal", WeightNormal(self.mass * G * np.cos(self.incline)))

    @property
    def inertia(self) -> float:
        if self.radius is None:
            raise SceneError("scene has no radius, so no moment of inertia")
        return self.inertia_factor * self.mass * self.radius**2

    def supplies(self) -> set[str]:
        """Contact quantities this scene can provide to a law."""
        q = {"u", "t"}
        if self.area is not None:
            q |= {"A", "dAdt"}
        if self.normal is not None:
            q.add("N")
        return q

    def with_(self, **changes) -> "Scene":
        return attrs.evolve(self, **changes)

    # -- construction from a TOML [scene] table -------------------------------------
    @classmethod
    def from_spec(cls, spec: Mapping, kind: str, where: str, columns: Mapping[str, np.ndarray] | None = None,
                  t: np.ndarray | None = None) -> "Scene":
        """Build a scene from a ``[scene]`` table; ``where`` prefixes error messages (file name)."""
        columns = columns or {}
        known = {"mass", "radius", "inertia_factor", "u0", "omega0", "duration", "incline", "effects",
                 "area", "normal", "compliance", "materials", "spring"}
        extra = set(spec) - known
        if extra:
            raise SceneError(f"{where}: [scene] has unknown key(s) {sorted(extra)}; known: {', '.join(sorted(known))}")

        q = spec_reader(spec, where)
        effects = read_effects(spec, where)

        mass = q("mass", "kg")
        radius = q("radius", "m", required="spin" in effects or "slip-coupling" in effects)
        incline = q("incline", "rad", required=kind == "incline", positive=False)
        if incline is not None and not (0 < incline < math.pi / 2):
            raise SceneError(f"{where}: scene.incline must be between 0 and 90 deg, got {spec['incline']!r}")
        if kind == "incline":
            effects |= {"gravity"}
        inertia_factor = q("inertia_factor", "", default=0.4, required=False)
        if not inertia_factor <= 1.0:
            raise SceneError(f"{where}: scene.inertia_factor = {inertia_factor:g}: I = f m r^2 needs f <= 1 "
                             "(0.4 for a solid sphere, 2/3 for a thin shell)")
        spring = _spring_from_spec(spec, where, q, kind)
        u0 = q("u0", "m/s", required=kind not in ("impact-outcome", "spring-slider"), positive=False,
               default=spring.velocities[0] if spring else 0.0)
        omega0 = q("omega0", "rad/s", required=False, positive=False, default=0.0)

        for key in ("area", "normal", "compliance", "materials", "spring"):
            if key in spec and not isinstance(spec[key], Mapping):
                raise SceneError(f"{where}: scene.{key} must be a table, got {type(spec[key]).__name__} {spec[key]!r}")
        pair = materials_from_spec(spec["materials"], where, q)[0] if "materials" in spec else None
        area = _area_from_spec(spec.get("area"), where, q, columns, t)
        contact_time = getattr(area, "contact_time", None)
        normal = _normal_from_spec(spec.get("normal"), where, q, columns, t, mass, contact_time, spec, incline)
        contact_time = contact_time if contact_time is not None else getattr(normal, "contact_time", None)
        compliance = None
        if "compliance" in spec:
            compliance = compliance_from_spec(spec["compliance"], where, q, pair, radius)
            effects |= {"compliance"}
        elif "compliance" in effects:
            raise SceneError(f"{where}: effect 'compliance' needs a [scene.compliance] table "
                             "(model = 'linear' with stiffness and damping, or 'mindlin')")

        duration = q("duration", "s", required=False)
        if duration is None:
            if contact_time is not None and kind == "impact":
                duration = contact_time
            elif t is not None and len(t) and t[-1] > 0:
                duration = float(t[-1])
            elif kind != "impact-outcome":
                raise SceneError(f"{where}: [scene] needs 'duration' (no contact time or time column to take it from)")
            else:
                duration = 0.0
        try:
            return cls(kind=kind, mass=mass, u0=u0, duration=duration, radius=radius, inertia_factor=inertia_factor,
                       omega0=omega0, incline=incline, area=area, normal=normal, compliance=compliance,
                       effects=effects, spring=spring)
        except SceneError as exc:
            raise SceneError(f"{where}: {exc}") from None


def _column(columns, name, where, prefix, quantity):
    if "t" not in columns:
        raise SceneError(f"{where}: {prefix}.model = 'column' needs the time column 't'")
    if name != quantity:
        raise SceneError(f"{where}: {prefix}.column = {name!r}: the column must be the {quantity!r} column")
    if name not in columns:
        raise SceneError(f"{where}: {prefix}.column = {name!r} is not a column of the CSV (has: {', '.join(map(str, columns))})")
    return columns[name]


#: Keys each area and normal-force model reads; anything else is a typo that would be ignored.
AREA_KEYS = {"half-sine": {"peak", "contact_time"}, "constant": {"area"}, "growth": {"initial", "rate"},
             "column": {"column"}}
NORMAL_KEYS = {"half-sine": {"contact_time", "impulse", "normal_speed", "restitution"}, "constant": {"value"},
               "hertz": {"coefficient", "modulus", "radius"}, "column": {"column"}, "weight": set()}


def _known_keys(table, keys, where, label):
    extra = set(table) - set(keys)
    if extra:
        raise SceneError(f"{where}: {label} has unknown key(s) {sorted(extra)}; "
                         f"known: {', '.join(sorted(keys)) or 'none'}")


def _area_from_spec(a, where, q, columns, t):
    if a is None:
        return None
    p = "scene.area"
    model = a.get("model")
    if isinstance(model, str) and model in AREA_KEYS:
        _known_keys(a, AREA_KEYS[model] | {"model"}, where, f"[{p}] with model {model!r}")
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
        A = _column(columns, a.get("column", "A"), where, p, "A")
        if np.any(A < 0):
            raise SceneError(f"{where}: area column has negative values")
        try:
            return TableArea(t, A)
        except SceneError as exc:
            raise SceneError(f"{where}: {p}: {exc}") from None
    raise SceneError(f"{where}: {p}.model must be one of half-sine, constant, growth, column; got {model!r}")


def _normal_from_spec(n, where, q, columns, t, mass, contact_time, spec, incline):
    if n is None:
        return None
    p = "scene.normal"
    model = n.get("model")
    if isinstance(model, str) and model in NORMAL_KEYS:
        _known_keys(n, NORMAL_KEYS[model] | {"model"}, where, f"[{p}] with model {model!r}")
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
        return TableNormal(t, _column(columns, n.get("column", "N"), where, p, "N"))
    if model == "constant":
        return ConstantNormal(q("value", "N", n, p))
    if model == "weight":
        if incline is None:
            raise SceneError(f"{where}: {p}.model = 'weight' needs scene.incline")
        return WeightNormal(mass * G * math.cos(incline))
    raise SceneError(f"{where}: {p}.model must be one of half-sine, hertz, column, weight, constant; got {model!r}")


def _spring_from_spec(spec, where, q, kind):
    """[scene.spring]: stiffness [1/m per unit normal force], times and velocities of the load point."""
    if "spring" not in spec:
        if kind == "spring-slider":
            raise SceneError(f"{where}: a spring-slider needs a [scene.spring] table with 'stiffness', 'times' "
                             "and 'velocities'")
        return None
    if kind != "spring-slider":
        raise SceneError(f"{where}: [scene.spring] belongs to kind 'spring-slider', not {kind!r}")
    sp = spec["spring"]
    if not isinstance(sp, Mapping):
        raise SceneError(f"{where}: scene.spring must be a table, got {type(sp).__name__}")
    _known_keys(sp, {"stiffness", "times", "velocities"}, where, "[scene.spring]")
    lists = {}
    for key, unit in (("times", "s"), ("velocities", "m/s")):
        v = sp.get(key)
        if not isinstance(v, list) or not v:
            raise SceneError(f"{where}: scene.spring.{key} must be a non-empty list of quantities in {unit}")
        lists[key] = [to_si(x, unit, f"{where}: scene.spring.{key}[{i}]") for i, x in enumerate(v)]
    try:
        return SpringLoad(q("stiffness", "1/m", sp, "scene.spring"), lists["times"], lists["velocities"])
    except SceneError as exc:
        raise SceneError(f"{where}: scene.spring: {exc}") from None
