"""The paper's decomposition of the wear law, lambda A u = lambda u0 (1 - b) A + (lambda u0 b / (phi A0)) A dA/dt.

It rests on the truncated slip u ~ u0 (1 - b + b cos phi t) (eq 7), so it is computed for the series
fit only, never for the exact solution, whose slip is u0 exp(-b (1 - cos phi t)). The paper prints
the second factor as phi/A0; dimensionally it is 1 / (phi A0). Projected by least squares onto
mu N + mu eta' dA/dt it gives the mu and eta' the claim implies.
"""
from __future__ import annotations

import math

import attrs
import numpy as np

from ...physics.law import AreaSlipForm
from ...physics.registry import get_law
from ...physics.scene import HalfSineArea
from ..fitting.fit import FitResult


@attrs.frozen
class Decomposition:
    """The paper's two-term form of lambda A u (series fit only), and its projection onto mu N + mu eta' dA/dt."""

    b: float
    u0: float  # [m/s]
    c_area: float  # lambda u0 (1 - b) [N/m^2]
    c_area_rate: float  # lambda u0 b / (phi A0) [N s/m^4]
    mu: float  # implied mu [-]
    eta_prime: float  # implied eta' [N s/m^2]
    r2: float  # share of the decomposition force the projection reproduces

    def as_dict(self) -> dict:
        return attrs.asdict(self)



def decomposition(fw: FitResult) -> Decomposition | None:
    """The paper's decomposition of a wear-family fit solved by the series, projected onto
    mu N + mu eta' dA/dt; None for any other solver (the decomposition rests on the truncated slip)
    or a scene without the half-sine area and a normal-force model."""
    if fw.solver != "series" or not fw.ok:
        return None
    law = get_law(fw.law)
    d = fw.per_dataset[0]
    s = d.scene
    form = law.form(d.params)
    if not isinstance(form, AreaSlipForm) or not isinstance(s.area, HalfSineArea) or s.normal is None:
        return None
    A0, tc = s.area.peak, s.area.contact_time
    phi = math.pi / tc
    b = form.k * A0 / (s.mass * phi)
    c1 = form.k * s.u0 * (1 - b)
    c2 = form.k * s.u0 * b / (phi * A0)
    t = np.linspace(0.0, tc, 2001)
    A, dA = s.area(t)
    N = s.normal(t, A)
    F = c1 * A + c2 * A * dA
    basis = np.column_stack([N, dA])
    (a, c), *_ = np.linalg.lstsq(basis, F, rcond=None)
    r2 = 1.0 - float(np.sum((F - basis @ [a, c]) ** 2) / np.sum((F - F.mean()) ** 2))
    return Decomposition(b, s.u0, c1, c2, float(a), float(c / a) if a else math.nan, r2)
