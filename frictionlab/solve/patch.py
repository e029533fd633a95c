"""The massless contact patch of a scene with tangential compliance (effect 'compliance'): its slip u from
F(u) = k xi + c (w - u) and the force the spring and damper pass to the body (see ``frictionlab.solve.plan``)."""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from ..core.errors import SceneError
from ..physics.law import AreaSlipForm, NormalAreaRateForm


class CompliantPatch:
    """The compliant-patch methods of ``Plan`` (they read its scene, law, contact and force)."""

    def spring(self, t, y) -> tuple[float, float, float]:
        """(k [N/m], c [N s/m], loading rate (da/dt)/a [1/s]) of the tangential compliance at time t."""
        comp = self.scene.compliance
        if comp.model == "linear":
            return comp.stiffness, comp.damping, 0.0
        A, dAdt = self.area(np.array([t]), y[:, None], np.array([0.0]))
        return comp.spring(float(A[0]), float(dAdt[0]), 1.0 / self.kappa)

    def patch_slip(self, p, t, y) -> float:
        """Slip of the compliant contact patch: the root of F(u) + c u = k xi + c w (scalar state)."""
        k, c, _ = self.spring(t, y)
        w = float(self.rigid_slip(y))
        target = k * y[self.index("xi")] + c * w
        fast = self._patch_slip_closed_form(p, t, y, target, c)
        if fast is not None:
            return fast

        def g(u):
            f, _ = self.force(p, np.array([t]), y[:, None], np.array([u]))
            return f[0] + c * u - target

        tiny = 1e-12 * max(abs(w), abs(target) / c, 1e-300)
        lo, hi = g(-tiny), g(tiny)
        if lo <= 0.0 <= hi:
            return 0.0
        bound = target / c
        a, b = (0.0, bound) if hi < 0 else (bound, 0.0)
        ga, gb = g(a), g(b)
        if ga * gb > 0:  # law not monotone: widen once, then give up clearly
            a, b = (0.0, 2 * bound + math.copysign(tiny, bound)) if hi < 0 else (2 * bound - tiny, 0.0)
            if g(a) * g(b) > 0:
                raise SceneError(f"law '{self.law.name}': no contact-patch slip balances the tangential spring at t = {t:g} s")
        return brentq(g, a, b, xtol=1e-15 * max(abs(bound), 1e-300), rtol=4 * np.finfo(float).eps)

    def _patch_slip_closed_form(self, p, t, y, target, c):
        """The patch slip solved by hand for the laws' closed-form families, or None.

        F = k A u:  u = target / (k A + c).
        F = sign(u) Q, Q = a N + c' dA/dt >= 0 (Coulomb, area-rate while loading): the patch
        sticks (u = 0) while |target| <= Q, else slips with u = (target - sign(target) Q) / c.
        """
        form = self.law.form(p)
        if not isinstance(form, (AreaSlipForm, NormalAreaRateForm)):
            return None
        cq = self.contact(np.array([t]), y[:, None], np.array([0.0]))
        if isinstance(form, AreaSlipForm):
            return target / (form.k * float(cq.A[0]) + c)
        Q = form.a * float(cq.N[0]) + (form.c * float(cq.dAdt[0]) if form.c != 0.0 else 0.0)
        if Q < 0:
            return None  # the law pushes along the slip: let the root finder decide
        if abs(target) <= Q:
            return 0.0
        return (target - math.copysign(Q, target)) / c

    def patch_force(self, p, t, y) -> tuple[float, float]:
        """(F, u) for a compliant contact: the force the spring and damper pass to the body, and the patch slip.

        F = k xi + c (w - u) equals the law's F(u) while the patch slips; while it sticks
        (u = 0) it is the static friction the law's F(0) alone cannot express.
        """
        u = self.patch_slip(p, t, y)
        if u != 0.0:  # slipping: the balance F(u) = k xi + c (w - u) holds, take the law's value
            f, _ = self.force(p, np.array([t]), y[:, None], np.array([u]))
            return float(f[0]), u
        k, c, _ = self.spring(t, y)
        return k * float(y[self.index("xi")]) + c * float(self.rigid_slip(y)), 0.0
