"""Impact outcomes: one oblique impact per row, and what the ball does after it.

An ``impact-outcome`` dataset has one impact per CSV row (columns ``speed`` [m/s] and
``incidence`` [angle], optionally the inbound ``spin`` [rad/s]) and the ball in its TOML
``[scene]``. ``predict_outcomes`` simulates every row with ``simulate`` and returns, SI:

  rebound_spin    omega at the end of contact [rad/s], positive in the sense friction drives it
                  for positive tangential velocity (topspin for a ball sliding forward)
  tangential_cor  -(v_t2 - r omega_2) / (v_t1 - r omega_1): tangential restitution of the contact
                  point [-]; < 0 still sliding forward at rebound, 0 rolling, > 0 the contact point
                  reversed (possible only with tangential compliance, Maw, Barber and Fawcett 1976)
  rebound_angle   angle of the outbound velocity of the centre of mass [rad], from the same
                  reference as the incidence
  cm_tangential_cor      v_t2 / v_t1: tangential restitution of the centre of mass [-] (what Kharaz,
                  Gorham and Salman (2001) and the DEM benchmarks call the tangential restitution)
  normal_cor      v_n2 / v_n1 = e [-] (from the normal-contact model of the row)
  contact_rebound_angle  atan(v_c2 / v_n2) [rad], v_c2 = v_t2 - r omega_2: rebound angle of the contact
                  point, from the normal; negative when the contact point reversed
  psi1, psi2      Maw, Barber and Fawcett's normalized incidence and rebound angles of the contact point,
                  (kappa / mu) v_c1 / v_n1 and (kappa / mu) v_c2 / v_n2, kappa = 4 G*/E* from
                  [scene.materials] and mu the friction coefficient stated there (frictionlab.physics.contact)

Angles: ``incidence`` is measured from the surface normal (0 = head-on), so v_t = V sin(theta)
and v_n = V cos(theta); with ``angle_reference = "surface"`` in [scene] it is measured from the
surface (v_t = V cos, v_n = V sin) and so is the rebound angle. The outbound normal speed is e v_n.

Normal contact per row, ``[scene.normal]``:
  model = "half-sine"  N = Np sin(pi t / t_c), impulse m v_n (1 + e). Given ``contact_time`` and
      ``restitution``; with ``reference_speed`` v_ref both depend on the normal speed:
      t_c = contact_time (v_n / v_ref)^contact_time_exponent (default -1/5, Hertz's exponent) and
      e = restitution - restitution_slope (v_n - v_ref) [slope in s/m], kept within [0, 1].
  model = "hertz"  elastic Hertz impact of a sphere (radius r) on a flat: N = K delta^(3/2),
      K = (4/3) E* sqrt(r), E* the effective ``modulus`` (or from [scene.materials]); delta(t) = delta_m y(v_n t / delta_m) with
      y'' = -(5/4) y^(3/2), y(0) = 0, y'(0) = 1, delta_m = (5 m v_n^2 / (4 K))^(2/5), contact time
      2.943 delta_m / v_n. The elastic pulse has impulse 2 m v_n; it is scaled by (1 + e)/2 so the
      impulse is m v_n (1 + e) (restitution as for half-sine). Contact area A = pi r delta.
Contact area, ``[scene.area]`` (for laws that read A or dA/dt):
  model = "half-sine"  A = A0 sin(pi t / t_c) over the row's contact time; with a reference speed,
      A0 = peak (v_n / v_ref)^peak_exponent (default 4/5: Hertz, A_max = pi r delta_m ~ v_n^(4/5)); v_ref is
      the area's reference_speed, else the normal model's.
  model = "hertz"  A = pi r delta(t) of the Hertz pulse (the default with a Hertz normal force).
Tangential: the law, with the scene's effects (default spin and slip coupling, so slip stops and
the ball rolls as the law allows), optional [scene.compliance] (model = "linear" with stiffness and
damping, or "mindlin": k_t = 8 G* a(t) with G* from [scene.materials] or ``shear_modulus``).
Materials, ``[scene.materials]``: ball_young, ball_poisson, surface_young, surface_poisson and the
friction coefficient the source states (``friction``, used only to normalize psi1 and psi2).
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np

from ..core.errors import DatasetError, SceneError
from ..physics.contact import normalized_angle
from .outcomescene import (
    ANGLE_REFERENCES,
    HertzPulse,
    Inbound,
    OutcomeScene,
    SpeedLaw,
    hertz_shape,
)
from ..core.fpstate import with_own_errstate

if TYPE_CHECKING:  # annotations only
    from ..physics.scene import SceneSource
    from ..physics.law import FrictionLaw

__all__ = ["ANGLE_REFERENCES", "OUTCOMES", "HertzPulse", "Inbound", "OutcomeScene", "SpeedLaw", "hertz_shape",
           "mdr_solvers", "predict_outcomes", "rows_of"]

#: Outcome observables and their SI units.
OUTCOMES = {"rebound_spin": "rad/s", "tangential_cor": "", "rebound_angle": "rad", "cm_tangential_cor": "",
            "normal_cor": "", "contact_rebound_angle": "rad", "psi1": "", "psi2": ""}


def rows_of(dataset) -> dict[str, np.ndarray]:
    """speed, incidence (and spin) columns of an impact-outcome dataset, checked."""
    c = dataset.columns
    for col in ("speed", "incidence"):
        if col not in c:
            raise DatasetError(f"dataset '{dataset.name}': an impact-outcome dataset needs a '{col}' column")
    return {"speed": c["speed"], "incidence": c["incidence"], "spin": c.get("spin", np.zeros(len(c["speed"])))}


def _rows(law, dataset_or_scene, speed, incidence, spin):
    """(rows, fixed parameters, OutcomeScene) of a Dataset or of an OutcomeScene with row arrays."""
    if not isinstance(dataset_or_scene, OutcomeScene) and hasattr(dataset_or_scene, "columns"):  # a Dataset
        ds = dataset_or_scene
        if ds.kind != "impact-outcome":
            raise DatasetError(f"dataset '{ds.name}' is a {ds.kind} dataset; predict_outcomes needs an impact-outcome one")
        return rows_of(ds), {k: v for k, v in ds.fixed.items() if k in law.param_names}, ds.scene
    if isinstance(dataset_or_scene, OutcomeScene):
        if speed is None or incidence is None:
            raise SceneError("predict_outcomes with an OutcomeScene needs speed [m/s] and incidence [rad] arrays")
        speed, incidence = np.broadcast_arrays(np.atleast_1d(np.asarray(speed, dtype=float)),
                                               np.atleast_1d(np.asarray(incidence, dtype=float)))
        spin = np.zeros(speed.shape) if spin is None else np.broadcast_to(np.asarray(spin, dtype=float), speed.shape)
        return {"speed": speed, "incidence": incidence, "spin": spin}, {}, dataset_or_scene
    raise SceneError(f"predict_outcomes: expected an impact-outcome Dataset or an OutcomeScene, "
                     f"got {type(dataset_or_scene).__name__}")


@with_own_errstate
def predict_outcomes(law: str | FrictionLaw, dataset_or_scene: SceneSource | OutcomeScene,
                     params: Mapping[str, float] | None = None, solver: str = "ode", *,
                     speed: np.ndarray | None = None, incidence: np.ndarray | None = None,
                     spin: np.ndarray | None = None, rtol: float = 1e-10) -> dict[str, np.ndarray]:
    """Simulate every impact and return its outcomes (SI arrays, one entry per row).

    dataset_or_scene: an impact-outcome Dataset (its rows and ``[fixed]`` parameters) or an
    OutcomeScene with ``speed`` [m/s], ``incidence`` [rad] (and ``spin`` [rad/s]) arrays.
    Returns every observable of OUTCOMES (psi1 and psi2 only when the scene has [scene.materials]
    with a stated friction coefficient), and per row the
    speed, incidence, normal_speed, tangential_speed, restitution, contact_time [s],
    rebound_speed_t (v_t2) [m/s] and rolled (slip stopped during contact, bool).
    """
    from ..physics.registry import get_law

    law = get_law(law)
    rows, fixed, template = _rows(law, dataset_or_scene, speed, incidence, spin)
    p = law.resolve({**fixed, **(params or {})})
    imps = _inbound(template, rows)
    if getattr(template.compliance, "model", None) == "mindlin-deresiewicz":
        v2, w2, rolled = _mdr_rebounds(law, imps, p, template)
    else:
        v2, w2, rolled = _rebounds(law, imps, p, solver, rtol)
    return _outcomes(template, rows, imps, v2, w2, rolled)


def predict_outcomes_many(law, scene: OutcomeScene, params_list, *, speed, incidence, spin=None):
    """``predict_outcomes(law, scene, params, 'exact', ...)`` for each parameter set of ``params_list``: the
    closed forms of every set's impacts in one call of the batch engine (a fit's start scan). None where that
    path does not apply (no closed-form batch: one row, Mindlin-Deresiewicz compliance) or refuses the batch;
    then ``predict_outcomes`` one set at a time gives each answer or error."""
    from ..physics.registry import get_law
    from .batch import simulate_batch
    from .solvers.exact import form_branch

    law = get_law(law)
    rows, fixed, template = _rows(law, scene, speed, incidence, spin)
    imps = _inbound(template, rows)
    if len(imps) < 2 or getattr(template.compliance, "model", None) == "mindlin-deresiewicz":
        return None
    n, out = len(imps), [None] * len(params_list)
    try:
        ps = [law.resolve({**fixed, **(params or {})}) for params in params_list]
        groups: dict = {}  # sets by the branch the engine takes for a whole batch (form_branch): each its own answer
        for j, q in enumerate(ps):
            groups.setdefault(form_branch(law.form(q)), []).append(j)
        t = np.array([[0.0, imp.contact_time] for imp in imps])
        for js in groups.values():
            p = {name: np.repeat([ps[j][name] for j in js], n) for name in law.param_names}
            br = simulate_batch(law, _scene_batch(imps).tile(len(js)), p, t=np.tile(t, (len(js), 1)), solver="exact")
            for i, j in enumerate(js):
                rows_i = slice(i * n, (i + 1) * n)
                out[j] = _outcomes(template, rows, imps, br.v[rows_i, -1], br.omega[rows_i, -1],
                                   ~np.isnan(br.stick_time[rows_i]))
    except Exception:  # a refusal, or a third-party law's error: one set at a time says which and why
        return None
    return out


def _outcomes(template, rows, imps, v2, w2, rolled):
    """The outcome arrays of the rows from their end-of-contact tangential velocity v2 and spin w2."""
    n = len(rows["speed"])
    out = {k: np.empty(n) for k in ("speed", "incidence", "normal_speed", "tangential_speed", "restitution",
                                     "contact_time", "rebound_spin", "tangential_cor", "rebound_angle",
                                     "rebound_speed_t", "cm_tangential_cor", "contact_rebound_angle")}
    out["rolled"] = np.zeros(n, dtype=bool)
    r = template.radius
    for i, imp in enumerate(imps):
        slip_in = imp.tangential_speed - r * imp.spin
        vn2 = imp.restitution * imp.normal_speed
        angle = math.atan2(v2[i], vn2) if template.angle_reference == "normal" else math.atan2(vn2, v2[i])
        cm_cor = v2[i] / imp.tangential_speed if imp.tangential_speed != 0.0 else math.nan
        for k, v in (("speed", rows["speed"][i]), ("incidence", rows["incidence"][i]),
                     ("normal_speed", imp.normal_speed), ("tangential_speed", imp.tangential_speed),
                     ("restitution", imp.restitution), ("contact_time", imp.contact_time), ("rebound_spin", w2[i]),
                     ("tangential_cor", 0.0 - (v2[i] - r * w2[i]) / slip_in), ("rebound_angle", angle),
                     ("rebound_speed_t", v2[i]), ("cm_tangential_cor", cm_cor),
                     ("contact_rebound_angle", math.atan2(v2[i] - r * w2[i], vn2))):
            out[k][i] = v
    out["rolled"][:] = rolled
    out["normal_cor"] = out["restitution"].copy()
    if template.materials is not None and template.friction is not None:
        kappa, mu = template.materials.stiffness_ratio, template.friction
        vc1 = out["tangential_speed"] - r * np.asarray(rows["spin"], dtype=float)
        out["psi1"] = normalized_angle(vc1, out["normal_speed"], mu, kappa)
        out["psi2"] = normalized_angle(np.tan(out["contact_rebound_angle"]), 1.0, mu, kappa)
    return out


MDR_NEEDS_COULOMB = ("compliance model 'mindlin-deresiewicz' gives every point of the contact its own Coulomb limit "
                     "(mu times the local pressure); law '{law}' is not of the Coulomb form F = mu N")


def mdr_solvers(law) -> dict[str, str | None]:
    """``predict.applicable_solvers`` for a template with Mindlin-Deresiewicz compliance: its own fixed-step
    integrator (frictionlab.physics.mdr) runs under the name 'ode' for laws of the Coulomb form; nothing else applies."""
    from ..physics.law import NormalAreaRateForm

    form = law.form(law.defaults())
    if not (isinstance(form, NormalAreaRateForm) and form.c == 0.0):
        why = MDR_NEEDS_COULOMB.format(law=law.name)
        return {"exact": why, "series": why, "ode": why}
    why = "compliance model 'mindlin-deresiewicz' is integrated by frictionlab.physics.mdr (solver 'ode')"
    return {"exact": why, "series": why, "ode": None}


def _mdr_rebounds(law, imps, p, template):
    """End-of-contact tangential velocity [m/s] and spin [rad/s] of every row with Mindlin-Deresiewicz
    compliance (frictionlab.physics.mdr, all rows in one vectorized integration), and whether the contact point
    ended rolling (|v - r omega| below 1e-6 of its inbound value; with compliance it rarely does)."""
    from ..physics import mdr
    from ..physics.law import NormalAreaRateForm

    form = law.form(p)
    if not (isinstance(form, NormalAreaRateForm) and form.c == 0.0 and form.a >= 0.0):
        raise SceneError(MDR_NEEDS_COULOMB.format(law=law.name))
    r, m = template.radius, template.mass
    inertia = template.inertia_factor * m * r * r
    tc = np.array([imp.contact_time for imp in imps])
    probe = np.linspace(0.0, 1.0, 201)[None, :] * tc[:, None]
    amax = np.sqrt(np.array([np.max(imp.scene.area(probe[i])[0]) for i, imp in enumerate(imps)]) / math.pi)
    meff = inertia / (r * r + inertia / m)  # effective mass of the contact point, m f / (1 + f)
    try:
        steps = mdr.steps_for(template.compliance.shear, amax, meff, tc)
    except ValueError as exc:
        raise SceneError(f"compliance model 'mindlin-deresiewicz': {exc}") from None
    t = np.linspace(0.0, 1.0, steps + 1)[None, :] * tc[:, None]
    N = np.array([imp.scene.normal(t[i]) for i, imp in enumerate(imps)])
    A = np.array([imp.scene.area(t[i])[0] for i, imp in enumerate(imps)])
    v0 = np.array([imp.tangential_speed for imp in imps])
    w0 = np.array([imp.spin for imp in imps])
    try:
        v2, w2 = mdr.impacts(t, N, A, form.a, template.compliance.shear, m, r, inertia, v0, w0,
                             springs=template.compliance.springs)
    except ValueError as exc:
        raise SceneError(f"compliance model 'mindlin-deresiewicz': {exc}") from None
    if not (np.all(np.isfinite(v2)) and np.all(np.isfinite(w2))):
        raise SceneError("compliance model 'mindlin-deresiewicz': the integration gave a non-finite rebound")
    rolled = np.abs(v2 - r * w2) <= 1e-6 * np.abs(v0 - r * w0)
    return v2, w2, rolled


#: The last few (template, rows) -> per-row impacts: a fit evaluates the same rows of one scene at every step.
_INBOUND: dict = {}


def _inbound(template: OutcomeScene, rows) -> tuple[Inbound, ...]:
    """Each row's Inbound (its scene), checked; the same tuple again for the same template object and rows."""
    key = (id(template),) + tuple(np.asarray(rows[k], dtype=float).tobytes() for k in ("speed", "incidence", "spin"))
    hit = _INBOUND.get(key)
    if hit is not None and hit[0] is template:  # the entry holds the template, so its id is not reused meanwhile
        return hit[1]
    imps = []
    for i in range(len(rows["speed"])):
        try:
            imps.append(template.impact(float(rows["speed"][i]), float(rows["incidence"][i]), float(rows["spin"][i])))
        except SceneError as exc:
            raise SceneError(f"row {i + 1}: {exc}") from None
        if imps[-1].tangential_speed - template.radius * imps[-1].spin == 0.0:
            raise SceneError(f"row {i + 1}: the contact point does not slip on arrival (v_t = r omega), "
                             "so its tangential restitution is undefined")
    if len(_INBOUND) >= 8:
        _INBOUND.pop(next(iter(_INBOUND)))
    _INBOUND[key] = (template, tuple(imps))
    return _INBOUND[key][1]


_BATCHES: dict = {}  # id(impacts) -> (impacts, SceneBatch), beside _INBOUND


def _scene_batch(imps: tuple):
    """The batch engine's SceneBatch of the rows' scenes: built once for the tuple ``_inbound`` returns."""
    from .batch import SceneBatch

    hit = _BATCHES.get(id(imps))
    if hit is not None and hit[0] is imps:
        return hit[1]
    batch = SceneBatch.from_scenes([imp.scene for imp in imps])  # may refuse: the caller falls back, nothing kept
    if len(_BATCHES) >= 8:
        _BATCHES.pop(next(iter(_BATCHES)))
    _BATCHES[id(imps)] = (imps, batch)
    return batch


def _rebounds(law, imps, p, solver, rtol):
    """Tangential velocity [m/s] and spin [rad/s] at the end of each impact, and whether its slip stopped.

    The closed forms run on the batch engine (``batch.simulate_batch``, one vectorized call for all
    rows; tests check it equals the row-by-row solve) when the rows' scenes share one structure;
    otherwise, for the ODE solver, or when the batch refuses, each row is simulated alone (which
    also names the row in any error)."""
    from ..core.errors import FrictionLabError
    from .solvers import simulate

    if solver == "exact" and len(imps) > 1:
        from .batch import simulate_batch

        try:
            t = np.array([[0.0, imp.contact_time] for imp in imps])
            br = simulate_batch(law, _scene_batch(imps), p, t=t, solver="exact")
            return br.v[:, -1], br.omega[:, -1], ~np.isnan(br.stick_time)
        except FrictionLabError:
            pass  # the row-by-row path below gives the answer or the error naming the row
    v2, w2, rolled = (np.empty(len(imps)) for _ in range(3))
    for i, imp in enumerate(imps):
        tr = simulate(law, imp.scene, p, solver=solver, t=np.array([0.0, imp.contact_time]), rtol=rtol)
        v2[i], w2[i], rolled[i] = float(tr.v[-1]), float(tr.omega[-1]), tr.stick_time is not None
    return v2, w2, rolled.astype(bool)
