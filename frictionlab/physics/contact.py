"""Contact mechanics of two elastic bodies: Hertz normal contact, Mindlin tangential stiffness, and the
normalized impact angles of Maw, Barber and Fawcett (1976). SI floats throughout.

Hertz (sphere of radius R on a flat, overlap delta [m]):
    F_n = (4/3) E* sqrt(R) delta^(3/2),  a = sqrt(R delta),  1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2.
Mindlin (no-slip tangential stiffness of the same contact):
    k_t = 8 G* a,  1/G* = (2 - nu1)/G1 + (2 - nu2)/G2,  G = E / (2 (1 + nu)).
The ratio of tangential to normal incremental stiffness, k_t / k_n = 8 G* a / (2 E* a) = 4 G*/E*, is the
``stiffness_ratio`` kappa; for like materials it is 2 (1 - nu) / (2 - nu).

Normalized angles (Maw, Barber and Fawcett, "The oblique impact of elastic spheres", Wear 38 (1976)
101-114, as quoted at https://th4.ilovetranslation.com/oG4oFPoRdOw=d: one non-dimensional parameter chi,
chi = 1.2558 for a thin diametral slice with nu = 0.28, and "Psi2 is negative for low values of Psi1".
The prefactor kappa / mu is the one that makes the elastic solution depend on chi alone; with
kappa = 4 G*/E* it reduces to MBF's 2 (1 - nu) / (2 - nu) for like materials, and chi below reproduces
their 1.2558, checked in tests/test_contact.py):
    Psi1 = (kappa / mu) * v_c1 / v_n1     (incidence of the contact point, v_c1 = v_t1 - r omega_1)
    Psi2 = (kappa / mu) * v_c2 / v_n2     (rebound of the contact point, v_n2 = e v_n1)
    chi  = (kappa / 2) (1 + m r^2 / I)    (= (1 - nu)(1 + r^2/k^2)/(2 - nu) for like materials, as in MBF)
Tangential compliance models (``[scene.compliance] model``): 'linear' (constant spring and damper),
'mindlin' (k_t = 8 G* a(t), Thornton's one-state history simplification, any law, ODE solvers) and
'mindlin-deresiewicz' (microslip and the full loading history by the Method of Dimensionality
Reduction, frictionlab.physics.mdr; Coulomb-form laws, impact outcomes).
Rigid-body Coulomb theory (``rigid_psi2``): the contact point slides throughout when
Psi1 >= 2 chi (1 + e), then Psi2 = (Psi1 - 2 chi (1 + e)) / e; below that it stops and rolls, Psi2 = 0.
"""
from __future__ import annotations

import math

import attrs
import numpy as np

from ..core.errors import SceneError


@attrs.frozen
class Material:
    """An isotropic elastic material: Young's modulus [Pa] and Poisson ratio [-]."""

    young: float
    poisson: float

    def __attrs_post_init__(self):
        if not (math.isfinite(self.young) and self.young > 0):
            raise SceneError(f"Young's modulus must be a positive number of Pa, got {self.young!r}")
        if not (math.isfinite(self.poisson) and -1.0 < self.poisson < 0.5):
            raise SceneError(f"Poisson ratio must be in (-1, 0.5), got {self.poisson!r}")

    @property
    def shear(self) -> float:
        """Shear modulus G = E / (2 (1 + nu)) [Pa]."""
        return self.young / (2.0 * (1.0 + self.poisson))


@attrs.frozen
class Pair:
    """Two bodies in contact (ball and surface): the effective moduli of their contact [Pa]."""

    ball: Material
    surface: Material

    @property
    def modulus(self) -> float:
        """E*: 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 [Pa]."""
        return 1.0 / sum((1.0 - m.poisson**2) / m.young for m in (self.ball, self.surface))

    @property
    def shear(self) -> float:
        """G*: 1/G* = (2 - nu1)/G1 + (2 - nu2)/G2 [Pa]."""
        return 1.0 / sum((2.0 - m.poisson) / m.shear for m in (self.ball, self.surface))

    @property
    def stiffness_ratio(self) -> float:
        """kappa = k_t / k_n = 4 G* / E* [-]."""
        return 4.0 * self.shear / self.modulus


def hertz_force(delta, modulus: float, radius: float):
    """Hertz normal force (4/3) E* sqrt(R) delta^(3/2) [N]; zero for delta <= 0."""
    return 4.0 / 3.0 * modulus * math.sqrt(radius) * np.maximum(delta, 0.0) ** 1.5


def contact_radius(delta, radius: float):
    """Hertz contact radius a = sqrt(R delta) [m]; zero for delta <= 0."""
    return np.sqrt(radius * np.maximum(delta, 0.0))


def mindlin_stiffness(a, shear: float):
    """Mindlin's no-slip tangential stiffness 8 G* a [N/m] of a contact of radius a [m]."""
    return 8.0 * shear * np.asarray(a)


def chi(stiffness_ratio: float, inertia_factor: float = 0.4) -> float:
    """MBF's parameter chi = (kappa/2)(1 + 1/f), f = I / (m r^2) (0.4 for a solid sphere)."""
    return 0.5 * stiffness_ratio * (1.0 + 1.0 / inertia_factor)


def normalized_angle(tangential, normal, mu: float, stiffness_ratio: float):
    """Psi = (kappa / mu) tangential / normal: the MBF normalized angle of a contact-point velocity [-]."""
    if not (mu > 0):
        raise SceneError(f"the normalized angle needs a positive friction coefficient, got {mu!r}")
    return stiffness_ratio / mu * np.asarray(tangential, dtype=float) / np.asarray(normal, dtype=float)


def rigid_psi2(psi1, chi_: float, restitution: float = 1.0):
    """Rigid-body Coulomb rebound angle Psi2(Psi1): sliding branch (Psi1 - 2 chi (1 + e)) / e, else 0 (rolling)."""
    psi1 = np.asarray(psi1, dtype=float)
    edge = 2.0 * chi_ * (1.0 + restitution)
    return np.where(psi1 >= edge, (psi1 - edge) / restitution, 0.0)


# --- tangential compliance models (the 'compliance' effect) --------------------------------------
def _positive(name):
    def check(instance, attribute, value):
        v = np.asarray(value)
        if v.dtype.kind not in "fi" or not np.all(np.isfinite(v)) or not np.all(v > 0):
            raise SceneError(f"{type(instance).__name__}.{name} must be a positive finite number, got {value!r}")
    return check


@attrs.frozen
class Compliance:
    """Linear tangential spring [N/m] and damper [N s/m] between the body and a massless contact patch.

    The damper must be positive: it makes the patch slip well defined for every law.
    """

    stiffness: float = attrs.field(validator=_positive("stiffness"))
    damping: float = attrs.field(validator=_positive("damping"))
    model = "linear"

    def spring(self, A, dAdt, meff):
        """(k [N/m], c [N s/m], loading rate [1/s]) at contact area A; constant for a linear spring."""
        return self.stiffness, self.damping, 0.0


@attrs.frozen
class MindlinCompliance:
    """Mindlin tangential stiffness k_t = 8 G* a(t), a = sqrt(A / pi) from the scene's contact area.

    History (a documented simplification of Mindlin-Deresiewicz, as Thornton et al. (2013) recommend
    for DEM): the spring force S obeys dS = k_t dxi while the contact grows (new annuli of the contact
    carry no traction: the force is not rescaled) and S = k_t xi_e while it shrinks (the traction of
    the lost annulus goes with it: S is scaled with a). The state xi_e = S / k_t [m] therefore obeys
    dxi_e/dt = (w - u) - xi_e (da/dt)/a while loading and (w - u) while unloading. The Coulomb limit
    |S| <= mu N comes from the patch slip (the law's force caps the spring): no microslip annulus.
    A damper c = 2 damping_ratio sqrt(k_t m_eff) keeps the patch slip well defined (m_eff = 1/kappa of
    the plan, 2m/7 for a rolling sphere); a floor of 1e-9 r on a keeps it positive at first contact.
    """

    shear: float = attrs.field(validator=_positive("shear"))  # G* [Pa]
    damping_ratio: float = attrs.field(default=0.01, validator=_positive("damping_ratio"))  # [-]
    radius_floor: float = 1e-12  # [m] smallest contact radius used for k_t and c
    model = "mindlin"

    def spring(self, A, dAdt, meff):
        a = max(math.sqrt(max(float(A), 0.0) / math.pi), self.radius_floor)
        k = 8.0 * self.shear * a
        c = 2.0 * self.damping_ratio * math.sqrt(k * meff)
        loading = float(dAdt) / (2.0 * max(float(A), math.pi * self.radius_floor**2)) if dAdt > 0 else 0.0  # (da/dt)/a
        return k, c, loading


@attrs.frozen
class MindlinDeresiewiczCompliance:
    """Mindlin-Deresiewicz tangential contact with microslip and the full loading history, solved by the
    Method of Dimensionality Reduction (frictionlab.physics.mdr): ``springs`` independent springs over the
    contact, each with stiffness 4 G* dx and its own Coulomb limit mu times its share of N(t).

    The local Coulomb limit needs a friction coefficient: it works with laws of the Coulomb form
    (F = mu N while sliding). Impact outcomes are integrated by ``frictionlab.physics.mdr.impacts`` (all rows
    at once); the trajectory solvers take 'linear' or 'mindlin' only.
    """

    shear: float = attrs.field(validator=_positive("shear"))  # G* [Pa]
    springs: int = attrs.field(default=400, validator=_positive("springs"))  # [-]
    model = "mindlin-deresiewicz"


COMPLIANCE_KEYS = {"linear": {"model", "stiffness", "damping"},
                   "mindlin": {"model", "shear_modulus", "damping_ratio"},
                   "mindlin-deresiewicz": {"model", "shear_modulus", "springs"}}


def compliance_from_spec(c, where: str, q, pair: Pair | None, radius: float | None):
    """A compliance model from a ``[scene.compliance]`` table (model 'linear', 'mindlin' or 'mindlin-deresiewicz')."""
    p = "scene.compliance"
    model = c.get("model", "linear")
    if model not in COMPLIANCE_KEYS:
        raise SceneError(f"{where}: {p}.model must be one of {', '.join(map(repr, COMPLIANCE_KEYS))}, got {model!r}")
    extra = set(c) - COMPLIANCE_KEYS[model]
    if extra:
        raise SceneError(f"{where}: [{p}] with model {model!r} has unknown key(s) {sorted(extra)}; "
                         f"known: {', '.join(sorted(COMPLIANCE_KEYS[model]))}")
    if model == "linear":
        return Compliance(q("stiffness", "N/m", c, p), q("damping", "N*s/m", c, p))
    shear = q("shear_modulus", "Pa", c, p, required=pair is None)
    if shear is None:
        shear = pair.shear
    if model == "mindlin-deresiewicz":
        n = c.get("springs", 400)
        if isinstance(n, bool) or not isinstance(n, int) or not 10 <= n <= 100_000:
            raise SceneError(f"{where}: {p}.springs must be an integer from 10 to 100000, got {n!r}")
        return MindlinDeresiewiczCompliance(shear, n)
    ratio = q("damping_ratio", "", c, p, required=False, default=0.01)
    floor = 1e-9 * radius if radius else 1e-12
    return MindlinCompliance(shear, ratio, floor)


MATERIAL_KEYS = {"ball_young", "ball_poisson", "surface_young", "surface_poisson", "friction"}


def materials_from_spec(m, where: str, q) -> tuple[Pair, float | None]:
    """(Pair, stated friction coefficient or None) from a ``[scene.materials]`` table.

    Keys: ball_young, ball_poisson, surface_young, surface_poisson (moduli with units, e.g. "380 GPa");
    optional ``friction``: the friction coefficient the source states, used only to normalize Psi1, Psi2.
    """
    p = "scene.materials"
    extra = set(m) - MATERIAL_KEYS
    if extra:
        raise SceneError(f"{where}: [{p}] has unknown key(s) {sorted(extra)}; known: {', '.join(sorted(MATERIAL_KEYS))}")
    ball = q("ball_young", "Pa", m, p), q("ball_poisson", "", m, p, positive=False)
    surface = q("surface_young", "Pa", m, p), q("surface_poisson", "", m, p, positive=False)
    try:
        pair = Pair(Material(*ball), Material(*surface))
    except SceneError as exc:
        raise SceneError(f"{where}: [{p}]: {exc}") from None
    return pair, q("friction", "", m, p, required=False)
