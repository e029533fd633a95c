"""Mindlin-Deresiewicz tangential contact with microslip, by the Method of Dimensionality Reduction (MDR).

Popov and Hess, "Method of Dimensionality Reduction in Contact Mechanics and Friction" (Springer 2015),
ch. 2 and 7; Popov and Hess, Facta Universitatis Mech. Eng. 12 (2014) 1-14. The 3D contact of a
sphere (radius R) on a flat is mapped onto a row of independent springs at x in [-a, a] (here
x in [0, a], each spring standing for its mirror image too), with the 1D profile g(x) = x^2 / R:

  normal spring      E* dx, compressed u_z(x) = d - x^2 / R  (so a = sqrt(R d), sum = Hertz's force)
  tangential spring  4 G* dx, 1/G* = (2 - nu1)/G1 + (2 - nu2)/G2  (sum over the contact: 8 G* a, Mindlin)
  Coulomb limit      |4 G* u_x(x)| <= mu E* u_z(x), spring by spring

A spring entering the contact starts with u_x = 0; one leaving it drops its displacement; while in
contact it moves with the rigid tangential displacement w of the bodies (stick) unless that would pass
its limit, where it slides and sits at the limit. For the uncoupled problem (normal force not
depending on the tangential one: Dundurs' constant zero) this reproduces exactly Cattaneo-Mindlin
under constant normal force, Mindlin-Deresiewicz under any history of normal and tangential load,
and microslip (the stick zone is the set of springs below their limit).

The normal-tangential coupling of dissimilar materials (Dundurs' beta, -0.23 for alumina on soda-lime
glass) is neglected, as in Maw, Barber and Fawcett (1976) and in DEM contact models.

Here the local normal load is distributed over the springs as the Hertz pressure of the 1D model,
q(x) proportional to (a^2 - x^2), and normalized to the normal force N(t) the scene's normal model
gives, so that the springs' limits sum to mu N exactly and the rigid sliding branch is reproduced
whatever the normal model (Hertz pulse or half-sine with an area). The tangential stiffness depends
only on G* and a(t) = sqrt(A(t) / pi). SI throughout.
"""
from __future__ import annotations

import math

import numpy as np

#: Springs over [0, a_max] and the smallest number of time steps of one impact.
SPRINGS = 400
MIN_STEPS = 1000
#: Time steps per period of the sticking tangential oscillation sqrt(8 G* a_max / m_eff), and the most
#: one impact may take (beyond it the contact is stiff enough to be treated as rigid).
STEPS_PER_PERIOD = 120
MAX_STEPS = 200_000


def grid(n: int = SPRINGS) -> np.ndarray:
    """Spring positions x / a_max (midpoints of n equal cells of [0, 1])."""
    return (np.arange(n) + 0.5) / n


def limits(a, N, mu: float, x) -> np.ndarray:
    """Coulomb limit of each spring's force [N]: mu N (a^2 - x^2)+ / sum (a^2 - x^2)+ (rows of a, N [m, N]; x [m])."""
    q = np.maximum(np.asarray(a, dtype=float)[..., None] ** 2 - x**2, 0.0)
    total = q.sum(axis=-1, keepdims=True)
    return mu * np.asarray(N, dtype=float)[..., None] * np.divide(q, total, out=np.zeros_like(q), where=total > 0)


def step(f, df, a, limit, x) -> np.ndarray:
    """One MDR update of the springs' forces f [N]: inside the contact (x < a) each moves by df (its stiffness
    times the rigid displacement increment) and is capped at its limit; outside it carries nothing."""
    return np.where(x < np.asarray(a)[..., None], np.clip(f + df, -limit, limit), 0.0)


def tangential_force(a, N, w, shear: float, mu: float, springs: int = 2000) -> np.ndarray:
    """Quasi-static tangential force [N] along a load path: contact radius a [m], normal force N [N] and
    rigid tangential displacement w [m] at successive instants (1D arrays), starting unloaded.
    Between instants the displacement changes monotonically (as in Mindlin-Deresiewicz)."""
    a, N, w = (np.asarray(v, dtype=float) for v in (a, N, w))
    amax = float(np.max(a))
    x = grid(springs) * amax
    k = 8.0 * shear * amax / springs  # stiffness of one spring [N/m] (4 G* dx, twice for x < 0)
    f = np.zeros(springs)
    out = np.empty(len(w))
    prev = 0.0
    for i in range(len(w)):
        f = step(f, k * (w[i] - prev), a[i], limits(a[i], N[i], mu, x), x)
        prev = w[i]
        out[i] = f.sum()
    return out


def steps_for(shear: float, amax, meff, duration) -> int:
    """Time steps of one impact: STEPS_PER_PERIOD per sticking tangential period, at least MIN_STEPS."""
    omega = np.sqrt(8.0 * shear * np.asarray(amax) / meff)
    periods = float(np.max(omega * np.asarray(duration))) / (2 * math.pi)
    if not math.isfinite(periods) or STEPS_PER_PERIOD * periods > MAX_STEPS:
        raise ValueError(f"the tangential contact oscillates {periods:.3g} times per impact (G* = {shear:.3g} Pa): "
                         f"more than {MAX_STEPS} explicit steps; so stiff a contact is rigid: use no compliance")
    return int(max(MIN_STEPS, math.ceil(STEPS_PER_PERIOD * periods)))


def impacts(t, N, A, mu: float, shear: float, mass: float, radius: float, inertia: float, v0, omega0,
            springs: int = SPRINGS):
    """Tangential impacts of spheres on a flat, all rows at once: (v [m/s], omega [rad/s]) at the end.

    t [s], N [N], A [m^2]: (rows, steps + 1) time grids of each row's contact and its normal force and
    contact area; v0, omega0: inbound tangential velocity of the centre and spin (rows). The friction
    force F on the body opposes the contact point's displacement w, dw/dt = v - r omega:
    m dv/dt = -F, I domega/dt = r F. Velocity Verlet on the body, MDR springs at each step
    (second order in the step for the body; the springs' update is exact for a monotone increment).
    """
    t, N, A = (np.atleast_2d(np.asarray(v, dtype=float)) for v in (t, N, A))
    a = np.sqrt(np.maximum(A, 0.0) / math.pi)
    amax = a.max(axis=1)
    if not np.all(amax > 0):
        raise ValueError("an impact row has no contact area: the Mindlin-Deresiewicz springs need A(t) > 0")
    from .mdr_kernel import impacts_loop

    x = grid(springs)[None, :] * amax[:, None]
    k = 8.0 * shear * amax / springs  # per-spring stiffness [N/m], per row
    v = np.array(v0, dtype=float).reshape(-1)
    omega = np.array(omega0, dtype=float).reshape(-1)
    impacts_loop(t, N, a, float(mu), np.ascontiguousarray(x), k, float(mass), float(radius), float(inertia), v, omega)
    return v, omega
