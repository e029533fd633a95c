"""The ball and contact of an impact-outcome dataset (``OutcomeScene``, its TOML ``[scene]``) and each row's
inbound impact as an ordinary Scene: normal-force and area models per row (half-sine, or the elastic
Hertz pulse), their speed dependence, compliance and materials (see ``frictionlab.solve.outcome``)."""
from __future__ import annotations

import math
from collections.abc import Mapping

import attrs
import numpy as np

from ..core.errors import SceneError
from ..physics.contact import (
    Compliance,
    MindlinCompliance,
    Pair,
    compliance_from_spec,
    materials_from_spec,
)
from . import hertzshape
from ..physics.scene import (
    HalfSineArea,
    HalfSineNormal,
    Scene,
    read_effects,
    spec_reader,
)

ANGLE_REFERENCES = ("normal", "surface")


# --- speed dependence ---------------------------------------------------------------------
@attrs.frozen
class SpeedLaw:
    """value(v_n) = value * (v_n / reference_speed)^exponent + slope (v_n - reference_speed); constant
    without a reference speed. Units: those of value; slope per m/s."""

    value: float
    reference_speed: float | None = None
    exponent: float = 0.0
    slope: float = 0.0

    def __call__(self, vn: float) -> float:
        if self.reference_speed is None:
            return self.value
        return self.value * (vn / self.reference_speed) ** self.exponent + self.slope * (vn - self.reference_speed)


# --- Hertz impact ----------------------------------------------------------------------------
def hertz_shape():
    """Dimensionless elastic Hertz impact: y'' = -(5/4) y^(3/2), y(0) = 0, y'(0) = 1.

    Returns (s_end, y, dy): the end of contact s_end = (4/5) B(2/5, 1/2) = 2.9432 and the solution y(s), y'(s)
    (``hertzshape``: integrated once by DOP853 at rtol 1e-13, tabulated, Hermite-interpolated), zero past s_end.
    """
    s_end = hertzshape.end()

    def inside(s):
        s = np.asarray(s, dtype=float)
        return (s >= 0) & (s <= s_end), np.clip(s, 0.0, s_end)

    def y(s):
        ok, c = inside(s)
        return np.where(ok, np.maximum(hertzshape.many(c)[0], 0.0), 0.0)

    def dy(s):
        ok, c = inside(s)
        return np.where(ok, hertzshape.many(c)[1], 0.0)

    return s_end, y, dy


@attrs.frozen
class HertzPulse:
    """One elastic Hertz impact: indentation delta(t) = delta_max y(v_n t / delta_max) for 0 <= t <= t_c."""

    stiffness: float  # K [N/m^1.5]
    delta_max: float  # [m]
    normal_speed: float  # [m/s]

    @property
    def time_scale(self) -> float:
        return self.delta_max / self.normal_speed

    @property
    def contact_time(self) -> float:
        return hertz_shape()[0] * self.time_scale

    def shape(self, t):
        """(y, dy/ds) at times t [s]; zero outside the contact."""
        s_end = hertzshape.end()
        if isinstance(t, (float, np.floating)) or np.ndim(t) == 0:  # one time (an ODE's right-hand side)
            s = float(t) / self.time_scale
            if not 0.0 <= s <= s_end:
                return np.float64(0.0), np.float64(0.0)
            y, dy = hertzshape.at(s)
            return np.float64(max(y, 0.0)), np.float64(dy)
        s = np.asarray(t, dtype=float) / self.time_scale
        inside = (s >= 0) & (s <= s_end)
        y, dy = hertzshape.many(np.clip(s, 0.0, s_end))
        return np.where(inside, np.maximum(y, 0.0), 0.0), np.where(inside, dy, 0.0)


@attrs.frozen
class HertzPulseNormal:
    """N(t) = factor K delta(t)^(3/2) [N]; factor = (1 + e)/2 scales the elastic impulse 2 m v_n to m v_n (1 + e)."""

    pulse: HertzPulse
    factor: float

    @property
    def contact_time(self) -> float:
        return self.pulse.contact_time

    def __call__(self, t, A=None):
        y, _ = self.pulse.shape(t)
        return self.factor * self.pulse.stiffness * (self.pulse.delta_max * y) ** 1.5


@attrs.frozen
class HertzPulseArea:
    """A(t) = pi r delta(t) [m^2], dA/dt = pi r v_n y'(s)."""

    pulse: HertzPulse
    radius: float

    @property
    def contact_time(self) -> float:
        return self.pulse.contact_time

    def __call__(self, t, x=None, speed=None):
        y, dy = self.pulse.shape(t)
        c = math.pi * self.radius
        return c * self.pulse.delta_max * y, c * self.pulse.normal_speed * dy


# --- the scene template ------------------------------------------------------------------------
@attrs.frozen
class Inbound:
    """One row's impact: the simulated scene and what the outcomes need (SI)."""

    scene: Scene
    tangential_speed: float  # v_t1, ball centre [m/s]
    normal_speed: float  # v_n1 [m/s]
    spin: float  # omega_1 [rad/s]
    restitution: float  # e [-]
    contact_time: float  # [s]


@attrs.frozen
class OutcomeScene:
    """The ball and contact models of an impact-outcome dataset; ``impact`` builds one row's Scene."""

    mass: float  # [kg]
    radius: float  # [m]
    normal: dict  # {"model": "half-sine" | "hertz", "contact_time": SpeedLaw | None, "modulus": float | None, "restitution": SpeedLaw}
    area: dict | None = None  # {"model": "half-sine" | "hertz", "peak": SpeedLaw | None}
    inertia_factor: float = 0.4
    effects: frozenset = frozenset({"spin", "slip-coupling"})
    compliance: Compliance | MindlinCompliance | None = None
    angle_reference: str = "normal"
    kind: str = "impact-outcome"
    materials: Pair | None = None
    friction: float | None = None  # the friction coefficient the source states (normalizes psi1, psi2)

    def impact(self, speed: float, incidence: float, spin: float = 0.0) -> Inbound:
        """The scene of one impact at ``speed`` [m/s] and ``incidence`` [rad], inbound ``spin`` [rad/s]."""
        if not (math.isfinite(speed) and speed > 0):
            raise SceneError(f"impact speed must be a positive number of m/s, got {speed!r}")
        if not (math.isfinite(incidence) and 0 < incidence < math.pi / 2):
            raise SceneError(f"incidence must be strictly between 0 and 90 deg, got {math.degrees(incidence):g} deg")
        if not math.isfinite(spin):
            raise SceneError(f"inbound spin must be finite, got {spin!r}")
        along, across = (math.sin, math.cos) if self.angle_reference == "normal" else (math.cos, math.sin)
        vt, vn = speed * along(incidence), speed * across(incidence)
        e = self.normal["restitution"](vn)
        e = min(max(e, 0.0), 1.0)
        if self.normal["model"] == "hertz":
            K = 4.0 / 3.0 * self.normal["modulus"] * math.sqrt(self.radius)
            pulse = HertzPulse(K, (5.0 * self.mass * vn * vn / (4.0 * K)) ** 0.4, vn)
            normal = HertzPulseNormal(pulse, (1.0 + e) / 2.0)
            tc = pulse.contact_time
        else:
            tc = self.normal["contact_time"](vn)
            if not (math.isfinite(tc) and tc > 0):
                raise SceneError(f"contact time at normal speed {vn:g} m/s is {tc!r} s; check scene.normal")
            normal, pulse = HalfSineNormal(self.mass * vn * (1.0 + e), tc), None
        area = None
        if self.area is not None:
            if self.area["model"] == "hertz":
                area = HertzPulseArea(pulse, self.radius)
            else:
                area = HalfSineArea(self.area["peak"](vn), tc)
        coupled = "slip-coupling" in self.effects
        scene = Scene(kind="impact", mass=self.mass, u0=vt - (self.radius * spin if coupled else 0.0), duration=tc,
                      radius=self.radius, inertia_factor=self.inertia_factor, omega0=spin, area=area, normal=normal,
                      compliance=self.compliance, effects=self.effects)
        return Inbound(scene, vt, vn, spin, e, tc)

    def example(self) -> Scene:
        """One representative impact (reference speed or 30 m/s, 45 deg): what a solver check needs."""
        vref = self.normal["restitution"].reference_speed or 30.0
        return self.impact(vref, math.pi / 4).scene

    # -- from a TOML [scene] table --------------------------------------------------------------
    @classmethod
    def from_spec(cls, spec: Mapping, where: str) -> "OutcomeScene":
        known = {"mass", "radius", "inertia_factor", "effects", "angle_reference", "normal", "area", "compliance",
                 "materials"}
        extra = set(spec) - known
        if extra:
            raise SceneError(f"{where}: [scene] of an impact-outcome dataset has unknown key(s) {sorted(extra)}; "
                             f"known: {', '.join(sorted(known))}")
        q = spec_reader(spec, where)
        effects = read_effects(spec, where, default=("spin", "slip-coupling"))
        if not {"spin", "slip-coupling"} & effects:
            raise SceneError(f"{where}: scene.effects must include 'spin' (and usually 'slip-coupling'): "
                             "the outcomes are the rebound spin and the contact point's restitution")
        ref = spec.get("angle_reference", "normal")
        if ref not in ANGLE_REFERENCES:
            raise SceneError(f"{where}: scene.angle_reference must be 'normal' or 'surface', got {ref!r}")
        mass, radius = q("mass", "kg"), q("radius", "m")
        inertia_factor = q("inertia_factor", "", required=False, default=0.4)
        for key in ("normal", "area", "compliance", "materials"):
            if key in spec and not isinstance(spec[key], Mapping):
                raise SceneError(f"{where}: scene.{key} must be a table, got {type(spec[key]).__name__}")
        if "normal" not in spec:
            raise SceneError(f"{where}: an impact-outcome [scene] needs a [scene.normal] table "
                             "(model = 'half-sine' with contact_time and restitution, or 'hertz' with modulus)")
        pair, friction = materials_from_spec(spec["materials"], where, q) if "materials" in spec else (None, None)
        normal = _normal_spec(spec["normal"], where, q, pair)
        area = _area_spec(spec.get("area"), where, q, normal)
        compliance = None
        if "compliance" in spec:
            compliance = compliance_from_spec(spec["compliance"], where, q, pair, radius)
            effects |= {"compliance"}
            if compliance.model != "linear" and area is None:
                raise SceneError(f"{where}: compliance model '{compliance.model}' needs the contact area: use "
                                 "scene.normal.model = 'hertz' or a [scene.area] table")
        elif "compliance" in effects:
            raise SceneError(f"{where}: effect 'compliance' needs a [scene.compliance] table "
                             "(model = 'linear' with stiffness and damping, or 'mindlin')")
        try:
            return cls(mass=mass, radius=radius, normal=normal, area=area, inertia_factor=inertia_factor,
                       effects=effects, compliance=compliance, angle_reference=ref, materials=pair,
                       friction=friction)
        except SceneError as exc:
            raise SceneError(f"{where}: {exc}") from None


def _normal_spec(n, where, q, pair=None) -> dict:
    p = "scene.normal"
    model = n.get("model")
    known = {"model", "contact_time", "restitution", "reference_speed", "contact_time_exponent",
             "restitution_slope", "modulus"}
    extra = set(n) - known
    if extra:
        raise SceneError(f"{where}: [{p}] has unknown key(s) {sorted(extra)}; known: {', '.join(sorted(known))}")
    vref = q("reference_speed", "m/s", n, p, required=False)
    e = q("restitution", "", n, p, positive=False)
    if not 0 <= e <= 1:
        raise SceneError(f"{where}: {p}.restitution must be in [0, 1], got {n['restitution']!r}")
    slope = q("restitution_slope", "s/m", n, p, required=False, positive=False, default=0.0)
    if (slope or "contact_time_exponent" in n) and vref is None:
        raise SceneError(f"{where}: {p}: restitution_slope and contact_time_exponent need a reference_speed")
    out = {"model": model, "restitution": SpeedLaw(e, vref, 0.0, -slope), "contact_time": None, "modulus": None}
    if model == "half-sine":
        tc = q("contact_time", "s", n, p)
        exponent = q("contact_time_exponent", "", n, p, required=False, positive=False, default=-0.2)
        out["contact_time"] = SpeedLaw(tc, vref, exponent)
    elif model == "hertz":
        out["modulus"] = q("modulus", "Pa", n, p, required=pair is None)
        if out["modulus"] is None:
            out["modulus"] = pair.modulus
        if "contact_time" in n:
            raise SceneError(f"{where}: {p}.contact_time: a Hertz contact's duration follows from modulus and speed")
    else:
        raise SceneError(f"{where}: {p}.model must be 'half-sine' or 'hertz' for an impact-outcome scene, got {model!r}")
    return out


def _area_spec(a, where, q, normal) -> dict | None:
    p = "scene.area"
    if a is None:
        return {"model": "hertz", "peak": None} if normal["model"] == "hertz" else None
    model = a.get("model")
    extra = set(a) - {"model", "peak", "peak_exponent", "reference_speed"}
    if extra:
        raise SceneError(f"{where}: [{p}] has unknown key(s) {sorted(extra)}; "
                         "known: model, peak, peak_exponent, reference_speed")
    if model == "hertz":
        if normal["model"] != "hertz":
            raise SceneError(f"{where}: {p}.model = 'hertz' needs a Hertz normal force (scene.normal.model = 'hertz')")
        return {"model": "hertz", "peak": None}
    if model == "half-sine":
        vref = q("reference_speed", "m/s", a, p, required=False, default=normal["restitution"].reference_speed)
        peak = q("peak", "m^2", a, p)
        exponent = q("peak_exponent", "", a, p, required=False, positive=False, default=0.8)
        if normal["model"] == "hertz":
            raise SceneError(f"{where}: {p}.model = 'half-sine' with a Hertz normal force: use model = 'hertz'")
        return {"model": "half-sine", "peak": SpeedLaw(peak, vref, exponent)}
    raise SceneError(f"{where}: {p}.model must be 'half-sine' or 'hertz' for an impact-outcome scene, got {model!r}")


# --- prediction ------------------------------------------------------------------------------------
