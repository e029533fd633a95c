"""Scenes shared by the solver tests, built through the public API (SI floats)."""
from __future__ import annotations

import math

from frictionlab import Scene
from frictionlab.physics.scene import (
    ConstantArea,
    G,
    HalfSineArea,
    HalfSineNormal,
    WeightNormal,
)

# The paper's golf ball (Arakawa 2017): m = 46 g, r = 21.3 mm, I = 2 m r^2 / 5.
MASS, RADIUS = 0.046, 0.0213
# The paper's two impacts: V_i = 28 m/s and 61 m/s (u0 [m/s], t_c [s], A0 [m^2], lambda [Pa s/m]).
PAPER = {
    28: dict(u0=12.0, tc=500e-6, A0=130e-6, lam=1.81e6, b=0.81, theta_deg=13.0),
    61: dict(u0=27.0, tc=460e-6, A0=270e-6, lam=0.96e6, b=0.83, theta_deg=26.0),
}


def paper_impact(vi: int = 28, coupled: bool = False, **changes) -> Scene:
    """The paper's impact scene: half-sine area, spin, no gravity, (by default) no slip coupling."""
    c = PAPER[vi]
    effects = {"spin"} | ({"slip-coupling"} if coupled else set())
    s = Scene(kind="impact", mass=MASS, u0=c["u0"], duration=c["tc"], radius=RADIUS,
              area=HalfSineArea(c["A0"], c["tc"]), effects=frozenset(effects))
    return s.with_(**changes) if changes else s


def normal_impact(u0=12.0, vn=24.0, e=0.6, tc=500e-6, A0=130e-6, coupled=True, duration=None) -> Scene:
    """Impact with a half-sine normal force of impulse m vn (1 + e) and a half-sine area."""
    effects = {"spin"} | ({"slip-coupling"} if coupled else set())
    return Scene(kind="impact", mass=MASS, u0=u0, duration=duration or tc, radius=RADIUS,
                 area=HalfSineArea(A0, tc), normal=HalfSineNormal(MASS * vn * (1 + e), tc),
                 effects=frozenset(effects))


def incline(alpha_deg=20.0, u0=1.0, mass=0.1, duration=2.0, area=None) -> Scene:
    """A block on an incline: gravity along it, N = m g cos(alpha), no spin."""
    a = math.radians(alpha_deg)
    return Scene(kind="incline", mass=mass, u0=u0, duration=duration, incline=a,
                 area=ConstantArea(area) if area is not None else None,
                 normal=WeightNormal(mass * G * math.cos(a)), effects=frozenset({"gravity"}))
