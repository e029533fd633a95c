"""Physical plausibility of a best fit: does its trajectory stay in a plausible range, and does it
rest on a parameter that does nothing?

Checked on the best-fit trajectory of every fitted dataset (for an impact-outcome set: of every
impact row), law-agnostic:

* range: the slip |u| or the contact speed of the spin r |omega| exceeds ``RANGE`` (10) times the
  speed the experiment starts from (the initial slip, the inbound speed of an impact, or for a body
  released from rest the largest observed velocity; for a spring-slider its fastest load-point velocity). A friction law only takes speed away; ten
  times the starting speed means the law pumped the motion.
* work: the friction force does net negative work over the record, W = integral of F u dt <
  -``WORK_TOL`` x integral of |F u| dt: friction as a net source of energy.
* no effect: a fitted law parameter that can be set to 0 (0 within its bounds) changes the weighted
  chi2 by no more than round-off, ``NIL_REL`` x max(chi2, n) (in units of the dataset's variance):
  the parameter's effect is structurally nil, not merely insignificant (a parameter within a
  standard error or so of 0 is an ordinary fit result, never flagged): the fit rests on a parameter without
  effect (e.g. eta' dA/dt integrates to zero over a closed contact pulse). Found by sensitivity,
  never by law name.

``check_plausibility`` returns (flags: one sentence each, numbers: the measured values, SI).
"""
from __future__ import annotations

import math
import warnings

import numpy as np

RANGE = 10.0
WORK_TOL = 0.01
NIL_REL = 1e-9  # a change of chi2 below this fraction of max(chi2, n) is round-off: no effect at all


def _trajectories(law, d):
    """(trajectory, reference speed [m/s], label) per simulated motion of one DatasetFit."""
    from ...solve.solvers import simulate

    scene = d.scene
    if d.target.t is not None:
        tr = d.trajectory(law, n=401)
        ref = abs(scene.u0)
        spring = getattr(scene, "spring", None)
        if spring is not None:  # a spring-slider is driven at its load-point velocities, not only the first
            ref = max(ref, max(abs(v) for v in spring.velocities))
        if d.target.observable in ("v", "u"):
            ref = max(ref, float(np.max(np.abs(d.target.y))))
        yield tr, ref, d.name
        return
    if not hasattr(scene, "impact"):
        return
    if getattr(scene.compliance, "model", None) == "mindlin-deresiewicz":
        return  # frictionlab.physics.mdr gives outcomes, not trajectories; its springs hold the Coulomb limit by construction
    from ...solve.outcome import rows_of

    rows = rows_of(d.target.dataset)
    for i in range(len(rows["speed"])):
        imp = scene.impact(float(rows["speed"][i]), float(rows["incidence"][i]), float(rows["spin"][i]))
        t = np.linspace(0.0, imp.contact_time, 201)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            tr = simulate(law, imp.scene, d.params, solver=d.solver, t=t)
        yield tr, float(rows["speed"][i]), f"{d.name} row {i + 1}"


def check_plausibility(law, per, model, slots, values, likelihood) -> tuple[list[str], dict]:
    """Flags and numbers for a best fit (see the module docstring). ``model`` evaluates the weighted
    residual for SI slot values (fitting._Model); ``values`` are the best-fit SI values by slot."""
    from ...core.errors import FrictionLabError

    flags, numbers = [], {}
    worst_u, worst_spin, worst_work = (0.0, ""), (0.0, ""), (0.0, "")
    try:
        for d in per:
            for tr, ref, label in _trajectories(law, d):
                if not ref > 0:
                    continue
                u = float(np.max(np.abs(tr.u))) / ref
                if u > worst_u[0]:
                    worst_u = (u, label)
                if d.scene.radius is not None and np.any(tr.omega):
                    w = float(np.max(np.abs(tr.omega))) * d.scene.radius / ref
                    if w > worst_spin[0]:
                        worst_spin = (w, label)
                power = tr.force * tr.u
                total = float(np.trapezoid(np.abs(power), tr.t))
                if total > 0:
                    frac = float(np.trapezoid(power, tr.t)) / total
                    if frac < worst_work[0]:
                        worst_work = (frac, label)
    except FrictionLabError as exc:  # a trajectory the solver cannot produce is itself implausible
        flags.append(f"the best-fit trajectory cannot be simulated densely: {exc}")
    numbers["max_slip_ratio"] = worst_u[0]
    numbers["max_spin_ratio"] = worst_spin[0]
    numbers["work_fraction"] = worst_work[0]
    for (ratio, label), what in ((worst_u, "slip |u|"), (worst_spin, "spin contact speed r |omega|")):
        if ratio > RANGE:
            flags.append(f"{what} reaches {ratio:.3g} times the starting speed ({label}; plausible: at most {RANGE:g}x)")
    if worst_work[0] < -WORK_TOL:
        flags.append(f"friction does net negative work ({worst_work[0]:+.2f} of its absolute work, {worst_work[1]}): "
                     "it supplies energy")
    effect = _effects(model, slots, values, likelihood)
    numbers["effect_dchi2"] = effect
    nil = NIL_REL * max(float(sum(d.chisqr for d in per)), float(sum(d.target.y.size for d in per)))
    for name, dchi in effect.items():
        if abs(dchi) <= nil:
            v = next(values[s.pname] for s in slots if s.display == name)
            flags.append(f"rests on {name} = {v:.3g}, which has no measurable effect: setting it to 0 changes "
                         f"chi2 by {dchi:.2g}, round-off (at most {nil:.2g})")
    return flags, numbers


def _effects(model, slots, values, likelihood) -> dict[str, float]:
    """Free law parameter -> change of the weighted chi2 (variance units) when it is set to 0."""
    base = model.residual(values)
    chi = float(base @ base)
    n_free = sum(s.vary for s in slots)
    unit = 1.0 if likelihood in ("known", "estimated", "stated") else max(chi / max(base.size - n_free, 1), np.finfo(float).tiny)
    out = {}
    for s in slots:
        if not (s.vary and s.kind == "law" and s.lower <= 0.0 <= s.upper and values[s.pname] != 0.0):
            continue
        trial = dict(values)
        trial[s.pname] = 0.0
        r = model.residual(trial)
        with np.errstate(over="ignore"):  # an effect too large for a float is simply a large effect
            effect = float(r @ r - chi) / unit if np.all(np.isfinite(r)) else math.inf
        out[s.display] = effect if math.isfinite(effect) else math.inf
    return out
