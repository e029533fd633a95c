"""What both batch engines share: the plan of a batch view, slip zeroed at a stick, bracketed roots, and the
outputs (slip, force, contact) on the grid from the states."""
from __future__ import annotations

import numpy as np

from ..core.errors import SolverError
from . import vecrk
from .plan import Plan, make_plan
from .scenebatch import take_params


def plan_of(law, view) -> Plan:
    return make_plan(view, law, "batch scene")


def zero_slip(plan, y):
    """Slip set to exactly zero at a stick event (states (d, k))."""
    y = np.array(y, dtype=float)
    y[0] = plan.scene.radius * y[plan.index("omega")] if plan.coupled else 0.0
    return y


def finish(law, batch, p, T, Y, sliding, need, into=None, dirs=None):
    """u, force, A and N on the output grid from the states, as ``segments.run`` does (written into the
    result arrays ``into`` when given; Y is then already theirs). ``dirs`` (n, m): where not 0, the slip
    direction of a sliding phase, which rounding must not flip (slip held at 0 there)."""
    view = batch.view(column=True)
    plan = plan_of(law, view)
    stuck = ~sliding
    u = plan.rigid_slip(Y)  # written in place below (a copy where it would alias the states): memory, not speed
    if into is not None:
        np.copyto(into["u"], u)
        u = into["u"]
    elif np.shares_memory(u, Y):
        u = u.copy()
    u[stuck] = 0.0
    if dirs is not None:
        held = dirs != 0
        u[held] = dirs[held] * np.maximum(dirs[held] * u[held], 0.0)
    c = plan.contact(T, Y, u)
    F = law.evaluate(take_params(p, slice(None), column=True), c)
    if into is not None:
        np.copyto(into["force"], F)
        F = into["force"]
    elif not F.flags.writeable or np.shares_memory(F, u):
        F = F.copy()
    np.copyto(F, np.broadcast_to(need, F.shape), where=stuck)
    A = c.A if c.A is not None else (plan.area(T, Y, u)[0] if plan.needs_area else None)  # a growth area reads x
    N = c.N
    for name, arr in (("states", Y), ("force", F)):
        if not all_finite(arr):
            bad = ~np.isfinite(arr) if arr.ndim == 2 else ~np.isfinite(arr).all(axis=0)
            i = int(np.argmax(bad.any(axis=1)))
            raise SolverError(f"batch: {name} became NaN or infinite for law '{law.name}' in scene {i}")

    def full(a, name):
        if a is None:
            return None
        if into is not None:
            np.copyto(into[name], a)
            return into[name]
        return a if np.shape(a) == u.shape else np.broadcast_to(a, u.shape).copy()

    omega = Y[plan.index("omega")] if plan.has_spin else np.zeros_like(u)
    theta = Y[plan.index("theta")] if plan.has_spin else np.zeros_like(u)
    return {"u": u, "v": Y[0], "omega": omega, "theta": theta, "force": F, "A": full(A, "A"), "N": full(N, "N")}


def all_finite(a) -> bool:
    """Every element finite: one summing pass (a sum is finite only if every term is), the elementwise
    test only when the sum is not (it may overflow)."""
    return bool(np.isfinite(np.sum(a)) or np.isfinite(a).all())


def root(make_fn, lo, hi, tol, gtol=0.0, glo=None, ghi=None):
    """First root of a per-scene sign change, fn > 0 at lo and <= 0 at hi; returns the hi side.

    make_fn(rows) gives fn for scenes rows (positions in lo/hi), see ``vecrk.root_bracketed``;
    glo, ghi: fn at lo and hi when a scan has them already."""
    if glo is None:
        fn = make_fn(np.arange(np.size(lo)))
        glo, ghi = fn(lo), fn(hi)
    return vecrk.root_bracketed(make_fn, lo, hi, glo, ghi, tol, gtol)
