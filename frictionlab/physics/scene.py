"""Scenes: a body, a contact history (area and normal-force models), a drive and named effects.

A scene is pure data in SI floats. It comes from a dataset's ``[scene]`` TOML table
(``Scene.from_spec``) or is built in Python. What to integrate is decided later by the
plan (``frictionlab.solve.plan``), from the scene's effects and the law's requirements.
The parts live in their own modules (area, normal, spring, sceneread) and are re-exported here.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Protocol

import attrs
import numpy as np

from ..core.errors import SceneError
from .area import AREA_KEYS, ConstantArea, GrowthArea, HalfSineArea, TableArea, area_from_spec
from .contact import (
    Compliance,
    MindlinCompliance,
    compliance_from_spec,
    materials_from_spec,
)
from .normal import (
    NORMAL_KEYS,
    ConstantNormal,
    G,
    HalfSineNormal,
    HertzNormal,
    TableNormal,
    WeightNormal,
    normal_from_spec,
)
from .sceneread import EFFECTS, finite, nonnegative, optional, positive, read_effects, spec_reader
from .spring import SpringLoad, spring_from_spec

__all__ = ["AREA_KEYS", "NORMAL_KEYS", "EFFECTS", "G", "KINDS", "Compliance", "ConstantArea", "ConstantNormal",
           "GrowthArea", "HalfSineArea", "HalfSineNormal", "HertzNormal", "MindlinCompliance", "Scene", "SpringLoad",
           "TableArea", "TableNormal", "WeightNormal", "read_effects", "spec_reader"]

KINDS = ("impact", "incline", "impact-outcome", "spring-slider")


class SceneSource(Protocol):
    """What carries a scene to simulate: a loaded dataset (``io.dataset.Dataset``), told by its interface."""

    name: str
    kind: str
    scene: Scene | None
    fixed: Mapping[str, float]


@attrs.frozen
class Scene:
    """Everything about an experiment except the friction law; SI floats throughout.

    Attributes
    ----------
    kind : str
        The scene kind: ``impact``, ``incline``, ``spring-slider``, ... (``frictionlab datasets template``
        lists them).
    mass : float
        Mass of the sliding body [kg].
    u0 : float
        Initial slip at the contact [m/s].
    duration : float
        Simulated time span [s].
    radius : float, optional
        Radius of a ball [m] (for spin).
    inertia_factor : float, default 0.4
        I = inertia_factor m r^2 (0.4 for a solid sphere).
    omega0 : float, default 0.0
        Initial spin [rad/s].
    incline : float, optional
        Incline angle [rad], between 0 and pi/2.
    area, normal : object, optional
        The contact-area and normal-force models (half-sine, constant, growth, Hertz, column, ...).
    compliance : object, optional
        Tangential compliance of the contact, for impact outcomes.
    effects : frozenset of str
        Extra effects of the scene.
    spring : SpringLoad, optional
        The driving spring and load-point history of a spring-slider.

    Raises
    ------
    SceneError
        A value outside its range (a negative mass, an incline not between 0 and pi/2, an unknown kind).
    """

    kind: str
    mass: float = attrs.field(validator=positive)  # [kg]
    u0: float = attrs.field(validator=finite)  # initial slip at the contact [m/s] (body velocity minus r omega0 with slip coupling)
    duration: float = attrs.field(validator=nonnegative)  # simulated time span [s]
    radius: float | None = attrs.field(default=None, validator=optional(positive))  # [m]
    inertia_factor: float = attrs.field(default=0.4, validator=positive)  # I = inertia_factor * m r^2
    omega0: float = attrs.field(default=0.0, validator=finite)  # [rad/s]
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
            finite(self, attrs.fields(Scene).incline, self.incline)
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
        """The body's moment of inertia [kg m^2], inertia_factor m r^2."""
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
        if self.spring is not None:  # the spring's load rate per unit normal force, k (V_lp - V)
            q.add("dmudt")
        return q

    def with_(self, **changes: object) -> "Scene":
        """A copy with the fields in ``changes`` replaced (SI values)."""
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
        incline, inertia_factor = _incline(q, spec, where, kind), _inertia_factor(q, where)
        if kind == "incline":
            effects |= {"gravity"}
        spring = spring_from_spec(spec, where, q, kind)
        u0 = q("u0", "m/s", required=kind not in ("impact-outcome", "spring-slider"), positive=False,
               default=spring.velocities[0] if spring else 0.0)
        omega0 = q("omega0", "rad/s", required=False, positive=False, default=0.0)

        for key in ("area", "normal", "compliance", "materials", "spring"):
            if key in spec and not isinstance(spec[key], Mapping):
                raise SceneError(f"{where}: scene.{key} must be a table, got {type(spec[key]).__name__} {spec[key]!r}")
        pair = materials_from_spec(spec["materials"], where, q)[0] if "materials" in spec else None
        area = area_from_spec(spec.get("area"), where, q, columns, t)
        contact_time = getattr(area, "contact_time", None)
        normal = normal_from_spec(spec.get("normal"), where, q, columns, t, mass, contact_time, spec, incline)
        contact_time = contact_time if contact_time is not None else getattr(normal, "contact_time", None)
        compliance = _compliance(spec, where, q, pair, radius, effects)
        if compliance is not None:
            effects |= {"compliance"}

        duration = _duration(q, where, kind, contact_time, t)
        try:
            return cls(kind=kind, mass=mass, u0=u0, duration=duration, radius=radius, inertia_factor=inertia_factor,
                       omega0=omega0, incline=incline, area=area, normal=normal, compliance=compliance,
                       effects=effects, spring=spring)
        except SceneError as exc:
            raise SceneError(f"{where}: {exc}") from None



def _incline(q, spec, where, kind):
    """scene.incline [rad], required for an incline, strictly between 0 and 90 deg."""
    incline = q("incline", "rad", required=kind == "incline", positive=False)
    if incline is not None and not (0 < incline < math.pi / 2):
        raise SceneError(f"{where}: scene.incline must be between 0 and 90 deg, got {spec['incline']!r}")
    return incline


def _inertia_factor(q, where):
    """scene.inertia_factor f of I = f m r^2 (default 0.4, a solid sphere)."""
    inertia_factor = q("inertia_factor", "", default=0.4, required=False)
    if not inertia_factor <= 1.0:
        raise SceneError(f"{where}: scene.inertia_factor = {inertia_factor:g}: I = f m r^2 needs f <= 1 "
                         "(0.4 for a solid sphere, 2/3 for a thin shell)")
    return inertia_factor


def _compliance(spec, where, q, pair, radius, effects):
    """The [scene.compliance] model, or None; effect 'compliance' without the table is an error."""
    if "compliance" in spec:
        return compliance_from_spec(spec["compliance"], where, q, pair, radius)
    if "compliance" in effects:
        raise SceneError(f"{where}: effect 'compliance' needs a [scene.compliance] table "
                         "(model = 'linear' with stiffness and damping, or 'mindlin')")
    return None


def _duration(q, where, kind, contact_time, t) -> float:
    """scene.duration [s]; else an impact's contact time, else the time column's last value."""
    duration = q("duration", "s", required=False)
    if duration is not None:
        return duration
    if contact_time is not None and kind == "impact":
        return contact_time
    if t is not None and len(t) and t[-1] > 0:
        return float(t[-1])
    if kind != "impact-outcome":
        raise SceneError(f"{where}: [scene] needs 'duration' (no contact time or time column to take it from)")
    return 0.0
