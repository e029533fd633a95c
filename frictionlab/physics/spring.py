"""The spring-slider's drive: a spring pulled at a load-point velocity that steps, from ``[scene.spring]``."""
from __future__ import annotations

import math
from collections.abc import Mapping

import attrs
import numpy as np

from ..core.errors import SceneError
from ..core.units import to_si
from .sceneread import known_keys, nonnegative, positive

@attrs.frozen(eq=False)
class SpringLoad:
    """A spring of stiffness k per unit normal force [1/m] pulled at a load-point velocity that steps.

    The load point moves at velocities[i] [m/s] from times[i] [s] on (times[0] = 0); a velocity of 0
    is a hold. The spring force per unit normal force, mu = K (x_lp - x) / N, obeys
    d mu/dt = k (V_lp - v): k = K / N is the stiffness per unit normal stress of the
    rate-and-state literature (k_c = (b - a) / Dc).

    ``mass`` [kg] is the slider's inertia: m dv/dt = K (x_lp - x) - F. With mass 0 (the default) the
    block is quasi-static, as in rsfmodel and most of the literature: the spring's load always equals
    the friction (see plan.py). A slider with mass can be followed through stick-slip.
    """

    stiffness: float = attrs.field(validator=positive)
    times: tuple = attrs.field(converter=lambda x: tuple(float(v) for v in x))
    velocities: tuple = attrs.field(converter=lambda x: tuple(float(v) for v in x))
    mass: float = attrs.field(default=0.0, validator=nonnegative)  # [kg]; 0: quasi-static

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

    @property
    def inertial(self) -> bool:
        """True when the slider has a mass (m dv/dt = K (x_lp - x) - F), False when it is quasi-static."""
        return self.mass > 0


def spring_from_spec(spec, where, q, kind):
    """[scene.spring]: stiffness [1/m per unit normal force], times and velocities of the load point, and the
    slider's optional mass [kg] (absent or 0: quasi-static)."""
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
    known_keys(sp, {"stiffness", "times", "velocities", "mass"}, where, "[scene.spring]")
    lists = {}
    for key, unit in (("times", "s"), ("velocities", "m/s")):
        v = sp.get(key)
        if not isinstance(v, list) or not v:
            raise SceneError(f"{where}: scene.spring.{key} must be a non-empty list of quantities in {unit}")
        lists[key] = [to_si(x, unit, f"{where}: scene.spring.{key}[{i}]") for i, x in enumerate(v)]
    try:
        return SpringLoad(q("stiffness", "1/m", sp, "scene.spring"), lists["times"], lists["velocities"],
                          mass=q("mass", "kg", sp, "scene.spring", required=False, positive=False, default=0.0))
    except SceneError as exc:
        raise SceneError(f"{where}: scene.spring: {exc}") from None


def runaway_cause(p, k: float, step: str = "", largest: float | None = None) -> str:
    """Why a spring-slider of stiffness k [1/m] ran away, from the rate-and-state parameters in p (SI) if any, and
    what to change; ``step``: the load point's velocity step it ran away after ('' if none), ``largest``: the
    largest step [m/s] from the same velocity found to run through (None: not known)."""
    mass = "give the slider a mass ([scene.spring] mass) to simulate"
    if not {"a", "b", "Dc"} <= set(p):
        return f"the law's friction falls with slip rate faster than the spring can follow; {mass} the slip"
    k_c = (p["b"] - p["a"]) / p["Dc"]
    against = f"the critical stiffness k_c = (b - a)/Dc = {k_c:.4g} /m"
    if k_c > 0 and math.isclose(k, k_c, rel_tol=CRITICAL_WITHIN):
        return (f"k = {k:.4g} /m is at {against}, where a perturbation neither grows nor decays; raise [scene.spring] "
                f"stiffness above k_c (e.g. {2 * k_c:.3g} 1/m), or {mass} the oscillation")
    if k < k_c:
        return (f"k = {k:.4g} /m is below {against}: stick-slip; raise [scene.spring] stiffness above {k_c:.4g} 1/m "
                f"(or choose a, b and Dc with (b - a)/Dc below k), or {mass} the stick-slip")
    return (f"k = {k:.4g} /m is above {against}, which is stable to small perturbations only: a rate-and-state slider "
            "runs away after large velocity jumps above k_c (Gu, Rice, Ruina and Tse 1984)"
            + (f", here {step}" if step else "") + "; make the velocity step smaller"
            + (f" (from the same velocity, steps up to about {largest * 1e6:.2g} um/s run through here)" if largest else "")
            + f", or {mass} the slip")


#: |k - k_c| / k_c within which a slider is said to sit at its critical stiffness.
CRITICAL_WITHIN = 1e-3


def step_at(t: float, times, velocities) -> str:
    """'after the load point's step at t = 5 s from 1 to 1e+06 um/s' for the segment of the schedule (start times
    [s], velocities [m/s]) holding time t [s], or '' where t follows no velocity change."""
    if times is None or len(times) < 2:
        return ""
    j = int(np.searchsorted(np.asarray(times, dtype=float), t, side="right")) - 1
    if j < 1 or velocities[j] == velocities[j - 1]:
        return ""
    return (f"after the load point's step at t = {times[j]:g} s from {velocities[j - 1] * 1e6:.3g} to "
            f"{velocities[j] * 1e6:.3g} um/s")


def runaway_message(law: str, v: float, t: float, velocities, p, k: float, limit: float, times=None,
                    largest: float | None = None) -> str:
    """The error of a quasi-static slider whose slip rate v [m/s] passed ``limit`` times the fastest load point at
    time t [s] (load-point velocities [m/s] from ``times`` [s]; law parameters p, SI; stiffness k [1/m]; the largest
    step that runs through, ``runaway_cause``): the stiffness against k_c and what to change first, then how far
    it ran."""
    cause = runaway_cause(p, k, step_at(t, times, velocities), largest)
    return (f"law '{law}' on a spring-slider: an unstable slider: {cause} "
            f"(its slip rate reached {v:.3g} m/s at t = {t:.6g} s, beyond {limit:g} times the fastest load-point "
            f"velocity, {max(velocities):.3g} m/s, as far as the quasi-static model follows a slider)")
