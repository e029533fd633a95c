"""Many scenes at once: vectorized closed forms and a vectorized Runge-Kutta engine, with stick per scene.

``simulate_batch(law, scenes, params, t, solver, rtol)`` returns a ``BatchResult`` of (n_scenes, n_t)
arrays. Scenes in one batch share their structure (kind, effects, area and normal-force model
types) and differ in numbers; a ``SceneBatch`` holds them column-wise, so a sweep of a million
scenes never builds a million Scene objects.

The physics is not written twice: a batch "view" is an ordinary Scene whose numeric fields are
arrays, and the ordinary Plan, law force, closed-form helpers (``solvers.exact``) and stuck-phase
formulas (``solvers.stick``) evaluate it elementwise. Laws must therefore broadcast their
parameters (every built-in law does: its force is arithmetic on the parameter values).

Solvers:
  'exact'   the closed forms of ``solvers.exact`` over the whole batch; stick located per scene by
            vectorized bracketed root finding (``vecrk.root_bracketed``). Scenes that break away after sticking
            (the area-rate law with eta' > 0 on an unloading contact) go on phase by phase, sliding from
            rest in closed form and perhaps sticking again, with the scenes still going in each round
            (``batchexact.exact_phases``); only a scene that starts at zero slip is re-run alone with the scalar solver.
  'RK45', 'DOP853'  scipy's tableaus, per-scene adaptive steps, dense output, zero slip located per
            scene (``frictionlab.solve.vecrk``, or ``frictionlab.solve.compiled`` where it serves: see Engines); stuck
            phases and breakaway handled per scene.
  'auto'    'exact' where the law and scene admit a closed form, else 'DOP853'.
Tolerances act on the same scaled problem as ``solvers.ode`` (time by the span, states by
``ode.state_scales``), so rtol means what it means for ``simulate(..., solver='ode:...')``;
with the same method the batch takes the same steps as solve_ivp (tests check the errors match).
``sweep.simulate_sweep`` runs a batch in chunks on an executor (local, concurrent.futures or Dask), streamed
to disk as Parquet and reduced per chunk where it outgrows memory.

Outputs: the default grid (n points over each scene's span) is one grid in scaled time, so the
integrator evaluates each step's outputs as one block; beyond CHUNK scenes the batch runs in chunks
integrated and finished straight into the result arrays (v, omega, theta are rows of one states
block), so memory stays below 2x the results and no chunk is copied.

Engines (measured by benchmarks/bench_batch.py, CPU time on a shared 2-core machine): the sliding phases
of the built-in laws' closed-form families (Coulomb, area-rate, wear, Couette) on rigid impacts and
inclines run in ``frictionlab.solve.compiled`` when numba is installed (``pip install 'frictionlab[fast]'``),
else, like every other law, in ``frictionlab.solve.vecrk`` (numpy); both take the same steps and give the same
numbers (tests/test_compiled.py checks them to 1e-12; bitwise on the benchmark machine for a law whose
force is its form's expression). At 10,000 scenes and rtol 1e-8 a DOP853 solve costs 5.5 to 9 us per
scene with the compiled phases (126x to 152x less than a loop of solve_ivp on a plain Python right-hand
side at the same method, rtol, event and accuracy) and 14 to 18 us with numpy (48x to 65x). With the
compiled phases, what is left is numpy over the output grid: slip, contact and force on the grid (the
half-sine's sine at every output) and the stuck phases' states, 3 us of a rolling Coulomb scene's 5.5.
Law plugins stay plain Python classes: a plugin, a law with memory or a scene model the kernel does not
know takes the numpy engine.
"""
from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import attrs
import numpy as np

from ..core.errors import SolverError
from ..physics.registry import get_law
from ..physics.trajectory import Trajectory
from . import vecrk
from .batchexact import run_exact
from .batchrk import run_rk
from .plan import make_plan
from .scenebatch import SceneBatch, batch_params, take_params
from .solvers import exact
from ..core.fpstate import with_own_errstate

if TYPE_CHECKING:  # annotations only
    from ..physics.law import FrictionLaw
    from ..physics.scene import Scene

__all__ = ["SOLVERS", "CHUNK", "SceneBatch", "BatchResult", "batch_params", "simulate_batch"]

SOLVERS = ("auto", "exact") + vecrk.METHODS
#: Scenes per chunk of ``simulate_batch``: beyond this the batch runs in chunks written into the result,
#: so working arrays stay those of one chunk (per-scene cost and memory flat in the number of scenes).
CHUNK = 8192


@attrs.frozen(eq=False)
class BatchResult:
    """Per-scene sampled motion, SI: t (n_t,) shared or (n, n_t); u, v, omega, theta, force (n, n_t);
    A, N (n, n_t) where the plan built them; stick_time (n,) [s], NaN where slip never stuck."""

    t: np.ndarray
    u: np.ndarray
    v: np.ndarray
    omega: np.ndarray
    theta: np.ndarray
    force: np.ndarray
    stick_time: np.ndarray
    A: np.ndarray | None = None
    N: np.ndarray | None = None
    solver: str = ""
    law: str = ""
    info: dict = attrs.field(factory=dict)

    def __len__(self) -> int:
        return self.u.shape[0]

    def trajectory(self, i: int) -> Trajectory:
        """Scene i as an ordinary Trajectory."""
        t = self.t if self.t.ndim == 1 else self.t[i]
        st = float(self.stick_time[i])
        return Trajectory(t=t, u=self.u[i], v=self.v[i], omega=self.omega[i], theta=self.theta[i], force=self.force[i],
                          A=None if self.A is None else self.A[i], N=None if self.N is None else self.N[i],
                          solver=f"batch:{self.solver}", law=self.law, stick_time=None if math.isnan(st) else st)


@with_own_errstate
def simulate_batch(law: str | FrictionLaw, scenes: Sequence[Scene] | SceneBatch,
                   params: Mapping[str, object] | Sequence[Mapping[str, object]] | None = None,
                   t: np.ndarray | None = None, solver: str = "auto", rtol: float = 1e-8,
                   atol: float | None = None, n: int = 201) -> BatchResult:
    """Simulate ``law`` on many scenes of one structure.

    scenes: a sequence of Scene or a SceneBatch; params: see ``batch_params``; t: sample times [s],
    (n_t,) shared or (n_scenes, n_t), default n points over each scene's duration; solver: 'auto',
    'exact', 'RK45' or 'DOP853'; rtol/atol: tolerances on the scaled problem (as ``solvers.ode``).
    """
    law = get_law(law)
    batch = scenes if isinstance(scenes, SceneBatch) else SceneBatch.from_scenes(scenes)
    if solver not in SOLVERS:
        raise SolverError(f"batch: unknown solver {solver!r}; choose one of {', '.join(SOLVERS)}")
    if not (0 < rtol < 1):
        raise SolverError(f"rtol must be in (0, 1), got {rtol}")
    nsc = batch.n
    p = batch_params(law, params, nsc)
    tgrid = _time_grid(batch, t, n)
    if nsc > CHUNK:
        return _chunked(law, batch, p, tgrid, solver, rtol, atol)
    out, solver, info = _simulate_chunk(law, batch, p, tgrid, solver, rtol, atol)
    return BatchResult(t=tgrid, solver=solver, law=law.name, info=info, **out)


def _simulate_chunk(law, batch, p, tgrid, solver, rtol, atol, into=None):
    """One chunk: (outputs, solver taken, info). ``into`` (see ``_chunked``) holds the result arrays' rows of
    these scenes, written in place (the states on the grid are integrated straight into them)."""
    nsc = batch.n
    T = np.broadcast_to(tgrid, (nsc, tgrid.shape[-1]))
    plan = make_plan(batch.view(), law, "batch scene")
    if plan.scene.spring is not None:
        raise SolverError("batch: spring-slider scenes are not supported; use simulate(..., solver='ode')")
    if plan.law_states:
        raise SolverError(f"batch: law '{law.name}' has internal state ({', '.join(law.state_names)}), which the "
                          "explicit batch engine does not integrate (stiff); use simulate(..., solver='ode')")
    if "xi" in plan.states:
        raise SolverError("batch: tangential compliance is not supported; use simulate(..., solver='ode')")
    if solver in ("auto", "exact"):
        p0 = {k: v if isinstance(v, float) else float(v[0]) for k, v in p.items()}
        plan0 = make_plan(batch.scene(0), law)
        try:
            exact.check(plan0, p0)
            solver = "exact"
        except SolverError:
            if solver == "exact":
                raise
            solver = "DOP853"
    if solver == "exact":
        out, info = run_exact(law, batch, p, T, into)
    else:
        out, info = run_rk(law, batch, p, T, solver, rtol, atol, into)
    info.update({"rtol": rtol, "atol": rtol if atol is None else atol} if solver != "exact" else {})
    return out, solver, info


def _chunked(law, batch, p, tgrid, solver, rtol, atol) -> BatchResult:
    """``simulate_batch`` chunk by chunk (CHUNK scenes each), written in place into the result arrays, so
    only one chunk's working arrays exist beside the results (memory below 2x the results at any n)."""
    plan = make_plan(batch.view(), law, "batch scene")
    n, m = batch.n, tgrid.shape[-1]
    states = np.empty((len(plan.states), n, m))  # the states on the grid: v, omega, theta are rows of it
    res = {"u": np.empty((n, m)), "force": np.empty((n, m)), "stick_time": np.empty(n),
           "A": np.empty((n, m)) if plan.needs_area else None,
           "N": np.empty((n, m)) if "N" in law.requires else None}
    parts = []
    for start in range(0, n, CHUNK):
        sl = slice(start, min(start + CHUNK, n))
        into = {k: None if a is None else a[sl] for k, a in res.items()} | {"states": states[:, sl]}
        out, s, info = _simulate_chunk(law, batch.subset(sl), take_params(p, sl), tgrid if tgrid.ndim == 1 else tgrid[sl],
                                       solver, rtol, atol, into)
        res["stick_time"][sl] = out["stick_time"]
        parts.append((s, info))
    solvers = {s for s, _ in parts}
    info = {"chunks": len(parts), "nfev": int(sum(i.get("nfev", 0) for _, i in parts)),
            **({"rtol": rtol, "atol": rtol if atol is None else atol} if "exact" not in solvers else {})}
    engines = {i["engine"] for _, i in parts if "engine" in i}
    if engines:
        info["engine"] = "+".join(sorted(engines))
    spin = plan.has_spin
    return BatchResult(t=tgrid, solver="+".join(sorted(solvers)), law=law.name, info=info, v=states[0],
                       omega=states[plan.index("omega")] if spin else np.zeros((n, m)),
                       theta=states[plan.index("theta")] if spin else np.zeros((n, m)), **res)


def _time_grid(batch, t, n):
    if t is None:
        dur = batch.values.get("duration")
        if dur is None:
            return np.linspace(0.0, batch.template.duration, n)
        return dur[:, None] * np.linspace(0.0, 1.0, n)[None, :]
    t = np.asarray(t, dtype=float)
    ok = t.ndim in (1, 2) and t.shape[-1] > 0 and np.all(np.isfinite(t)) and np.all(t >= 0)
    ok = ok and np.all(np.diff(t, axis=-1) >= 0) and (t.ndim == 1 or t.shape[0] == batch.n)
    if not ok:
        raise SolverError("batch: t must be (n_t,) or (n_scenes, n_t) non-decreasing times >= 0")
    return t
