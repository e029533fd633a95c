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
            (``_exact_phases``); only a scene that starts at zero slip is re-run alone with the scalar solver.
  'RK45', 'DOP853'  scipy's tableaus, per-scene adaptive steps, dense output, zero slip located per
            scene (``frictionlab.solve.vecrk``, or ``frictionlab.solve.compiled`` where it serves: see Engines); stuck
            phases and breakaway handled per scene.
  'auto'    'exact' where the law and scene admit a closed form, else 'DOP853'.
Tolerances act on the same scaled problem as ``solvers.ode`` (time by the span, states by
``ode.state_scales``), so rtol means what it means for ``simulate(..., solver='ode:...')``;
with the same method the batch takes the same steps as solve_ivp (tests check the errors match).
``simulate_sweep`` runs a batch in chunks on an executor (local, concurrent.futures or Dask).

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

import attrs
import numpy as np

from ..core.errors import ParameterError, SceneError, SolverError
from ..physics.registry import get_law
from ..physics.scene import HalfSineNormal, HertzNormal, Scene, WeightNormal
from ..physics.trajectory import Trajectory
from . import compiled, vecrk
from .plan import Plan, make_plan
from .solvers import exact, stick
from .solvers.ode import state_scales

SOLVERS = ("auto", "exact") + vecrk.METHODS
SCAN = 1024  # uniform points scanned for the first zero of slip when it is not provably monotone
#: Scenes per chunk of ``simulate_batch``: beyond this the batch runs in chunks written into the result,
#: so working arrays stay those of one chunk (per-scene cost and memory flat in the number of scenes).
CHUNK = 8192
MAX_SEGMENTS = 200
_NONNEGATIVE_N = (HalfSineNormal, HertzNormal, WeightNormal)
_TOP = ("mass", "u0", "duration", "radius", "inertia_factor", "omega0", "incline")


# --- scenes, column-wise -------------------------------------------------------------------
def _is_number(x) -> bool:
    return isinstance(x, (int, float, np.floating, np.integer)) and not isinstance(x, bool)


def _structure(scene: Scene):
    return (scene.kind, scene.effects, type(scene.area), type(scene.normal), scene.compliance is None,
            scene.radius is None, scene.incline is None)


def _model_fields(model):
    return [] if model is None else [f.name for f in attrs.fields(type(model)) if f.init]


@attrs.frozen(eq=False)
class SceneBatch:
    """n scenes of one structure: a template Scene plus per-scene values of its numeric fields.

    ``values`` maps a field path ('mass', 'u0', 'area.peak', 'normal.impulse', ...) to an (n,)
    array in SI; fields not listed take the template's value for every scene.
    """

    template: Scene
    values: dict
    n: int

    @classmethod
    def from_scenes(cls, scenes: Sequence[Scene]) -> "SceneBatch":
        scenes = list(scenes)
        if not scenes:
            raise SceneError("batch: no scenes given")
        first = scenes[0]
        key = _structure(first)
        for i, s in enumerate(scenes):
            if not isinstance(s, Scene):
                raise SceneError(f"batch: item {i} is a {type(s).__name__}, not a Scene")
            if _structure(s) != key:
                raise SceneError(f"batch: scene {i} differs in structure (kind, effects or area/normal model) from "
                                 "scene 0; simulate scenes of one structure per batch")
        values = {}
        paths = [(name, None) for name in _TOP]
        paths += [("area", f) for f in _model_fields(first.area)] + [("normal", f) for f in _model_fields(first.normal)]
        for top, field in paths:
            if field is None:
                col = [getattr(s, top) for s in scenes]
                path = top
            else:
                col = [getattr(getattr(s, top), field) for s in scenes]
                path = f"{top}.{field}"
            ref = col[0]
            if _is_number(ref):
                arr = np.array(col, dtype=float)
                if np.any(arr != arr[0]):
                    values[path] = arr
            elif any(c is not ref for c in col[1:]):
                raise SceneError(f"batch: scenes differ in {path}, which cannot be vectorized; "
                                 "share one model object or simulate them one by one")
        return cls(first, values, len(scenes))

    @classmethod
    def sweep(cls, template: Scene, values: Mapping[str, np.ndarray]) -> "SceneBatch":
        """A batch from a template and arrays for some of its numeric fields (all of one length)."""
        arrays = {k: np.asarray(v, dtype=float).ravel() for k, v in values.items()}
        sizes = {a.size for a in arrays.values()}
        if len(sizes) != 1:
            raise SceneError(f"batch: sweep arrays differ in length ({sorted(sizes)})")
        known = set(_TOP) | {f"area.{f}" for f in _model_fields(template.area)} | {
            f"normal.{f}" for f in _model_fields(template.normal)}
        bad = sorted(set(arrays) - known)
        if bad:
            raise SceneError(f"batch: unknown scene field(s) {bad}; known: {', '.join(sorted(known))}")
        return cls(template, arrays, sizes.pop())

    def view(self, idx=None, column: bool = False) -> Scene:
        """A Scene whose varying fields are arrays over scenes ``idx`` (shape (k,), or (k, 1) with column)."""
        def take(a):
            a = a if idx is None else a[idx]
            return a[:, None] if column else a

        return self._with({path: take(a) for path, a in self.values.items()})

    def scene(self, i: int) -> Scene:
        """Scene i as an ordinary Scene of floats."""
        return self._with({path: float(a[i]) for path, a in self.values.items()})

    def _with(self, values) -> Scene:
        top, area, normal = {}, {}, {}
        for path, a in values.items():
            head, _, field = path.partition(".")
            {"area": area, "normal": normal}.get(head, top)[field or head] = a
        s = self.template
        if area:
            top["area"] = attrs.evolve(s.area, **area)
        if normal:
            top["normal"] = attrs.evolve(s.normal, **normal)
        return attrs.evolve(s, **top) if top else s

    def subset(self, idx) -> "SceneBatch":
        """The scenes ``idx`` (an index array or slice) as a batch of their own."""
        idx = np.arange(self.n)[idx]
        return SceneBatch(self.template, {k: v[idx] for k, v in self.values.items()}, int(idx.size))

    def __len__(self) -> int:
        return self.n


# --- parameters ------------------------------------------------------------------------------
def batch_params(law, params, n: int) -> dict:
    """Law parameters for n scenes: name -> float (shared) or (n,) array, checked against bounds.

    ``params`` is None (defaults), a mapping of name -> scalar or (n,) array, or a sequence of n mappings.
    """
    if params is None:
        params = {}
    if not isinstance(params, Mapping):
        rows = list(params)
        if len(rows) != n:
            raise ParameterError(f"batch: {len(rows)} parameter sets for {n} scenes")
        names = set().union(*[set(r) for r in rows]) if rows else set()
        params = {k: np.array([r.get(k, law.spec(k).default) for r in rows], dtype=float) for k in names}
    out = {}
    for spec in law.params:
        v = params.get(spec.name, spec.default)
        a = np.asarray(v, dtype=float)
        if a.ndim == 0:
            a = float(a)
        elif a.shape != (n,):
            raise ParameterError(f"batch: parameter {spec.name} has shape {a.shape}, expected ({n},) or a scalar")
        bad = ~(np.isfinite(a) & (a >= spec.lower) & (a <= spec.upper))
        if np.any(bad):
            i = int(np.argmax(np.atleast_1d(bad)))
            val = np.atleast_1d(a)[i]
            raise ParameterError(f"law '{law.name}': {spec.name} = {val!r} {spec.unit} (scene {i}) is outside its bounds "
                                 f"[{spec.lower:g}, {spec.upper:g}]")
        out[spec.name] = a
    for k in params:
        law.spec(k)  # unknown names raise ParameterError
    return out


def _take_params(p, idx, column=False):
    def take(v):
        if isinstance(v, float):
            return v
        v = v[idx]
        return v[:, None] if column else v

    return {k: take(v) for k, v in p.items()}


# --- result ----------------------------------------------------------------------------------
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


# --- entry point -----------------------------------------------------------------------------
def simulate_batch(law, scenes, params=None, t=None, solver: str = "auto", rtol: float = 1e-8,
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
        out, info = _run_exact(law, batch, p, T, into)
    else:
        out, info = _run_rk(law, batch, p, T, solver, rtol, atol, into)
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
        out, s, info = _simulate_chunk(law, batch.subset(sl), _take_params(p, sl), tgrid if tgrid.ndim == 1 else tgrid[sl],
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


def simulate_sweep(law, scenes, params=None, t=None, solver: str = "auto", rtol: float = 1e-8,
                   atol: float | None = None, n: int = 201, executor=None, chunk: int = 5000) -> BatchResult:
    """``simulate_batch`` in chunks of ``chunk`` scenes, dispatched on ``executor`` (as in
    ``frictionlab.inference.bootstrap``: None runs here; a concurrent.futures executor or a dask.distributed
    Client spreads the chunks). Results are concatenated in scene order and equal the one-call result.
    """
    law = get_law(law)
    batch = scenes if isinstance(scenes, SceneBatch) else SceneBatch.from_scenes(scenes)
    p = batch_params(law, params, batch.n)
    tgrid = _time_grid(batch, t, n)
    chunk = max(1, int(chunk))
    jobs = []
    for start in range(0, batch.n, chunk):
        sl = slice(start, min(start + chunk, batch.n))
        args = (law.name, batch.subset(sl), _take_params(p, sl), tgrid if tgrid.ndim == 1 else tgrid[sl], solver, rtol,
                atol, n)
        jobs.append(args)
    if executor is None:
        parts = [simulate_batch(*a) for a in jobs]
    else:
        parts = [f.result() for f in [executor.submit(simulate_batch, *a) for a in jobs]]
    return _concat(parts, tgrid)


def _concat(parts, tgrid) -> BatchResult:
    def cat(name):
        arrs = [getattr(r, name) for r in parts]
        return None if any(a is None for a in arrs) else np.concatenate(arrs, axis=0)

    info = {"chunks": len(parts), "solver_per_chunk": [r.solver for r in parts],
            "nfev": int(sum(r.info.get("nfev", 0) for r in parts))}
    return BatchResult(t=tgrid, u=cat("u"), v=cat("v"), omega=cat("omega"), theta=cat("theta"), force=cat("force"),
                       stick_time=cat("stick_time"), A=cat("A"), N=cat("N"), solver=parts[0].solver, law=parts[0].law,
                       info=info)


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


def _plan(law, view) -> Plan:
    return make_plan(view, law, "batch scene")


def _zero_slip(plan, y):
    """Slip set to exactly zero at a stick event (states (d, k))."""
    y = np.array(y, dtype=float)
    y[0] = plan.scene.radius * y[plan.index("omega")] if plan.coupled else 0.0
    return y


def _finish(law, batch, p, T, Y, sliding, need, into=None, dirs=None):
    """u, force, A and N on the output grid from the states, as ``segments.run`` does (written into the
    result arrays ``into`` when given; Y is then already theirs). ``dirs`` (n, m): where not 0, the slip
    direction of a sliding phase, which rounding must not flip (slip held at 0 there)."""
    view = batch.view(column=True)
    plan = _plan(law, view)
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
    F = law.evaluate(_take_params(p, slice(None), column=True), c)
    if into is not None:
        np.copyto(into["force"], F)
        F = into["force"]
    elif not F.flags.writeable or np.shares_memory(F, u):
        F = F.copy()
    np.copyto(F, np.broadcast_to(need, F.shape), where=stuck)
    A = c.A if c.A is not None else (view.area(T, None, u)[0] if plan.needs_area else None)
    N = c.N
    for name, arr in (("states", Y), ("force", F)):
        if not _all_finite(arr):
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


def _all_finite(a) -> bool:
    """Every element finite: one summing pass (a sum is finite only if every term is), the elementwise
    test only when the sum is not (it may overflow)."""
    return bool(np.isfinite(np.sum(a)) or np.isfinite(a).all())


def _root(make_fn, lo, hi, tol, gtol=0.0, glo=None, ghi=None):
    """First root of a per-scene sign change, fn > 0 at lo and <= 0 at hi; returns the hi side.

    make_fn(rows) gives fn for scenes rows (positions in lo/hi), see ``vecrk.root_bracketed``;
    glo, ghi: fn at lo and hi when a scan has them already."""
    if glo is None:
        fn = make_fn(np.arange(np.size(lo)))
        glo, ghi = fn(lo), fn(hi)
    return vecrk.root_bracketed(make_fn, lo, hi, glo, ghi, tol, gtol)


# --- stuck phases ----------------------------------------------------------------------------
def _breakaway(law, batch, p, ids, ts, ys, t_end, last_dir):
    """Per stuck scene: (breakaway time or NaN, hold direction), as ``solvers.stick.breakaway``."""
    view = batch.view(ids, column=True)
    plan = _plan(law, view)
    pc = _take_params(p, ids, column=True)
    need = np.broadcast_to(stick.needed_force(plan), (ids.size, 1))[:, 0]
    hold = np.where(need != 0, np.sign(need), np.where(last_dir != 0, np.sign(last_dir), 1.0))
    known = _known_capacity(law, plan, pc, ids.size, ts, need)
    if known is not None:
        return known, hold, need
    tiny = hold * np.broadcast_to(stick.vanishing_slip(plan), (ids.size, 1))[:, 0]
    y3 = ys[:, :, None]

    def margin(tt):
        f, _ = plan.force(pc, tt, y3, np.broadcast_to(tiny[:, None], tt.shape))
        return hold[:, None] * f - np.abs(need)[:, None]

    frac = np.linspace(0.0, 1.0, stick.GRID)
    grid = ts[:, None] + (t_end - ts)[:, None] * frac[None, :]
    mg = margin(grid)
    bad = mg < 0
    first = np.argmax(bad, axis=1)
    tb = np.full(ids.size, np.nan)
    anyb = bad.any(axis=1)
    tb[anyb & (first == 0)] = ts[anyb & (first == 0)]
    ref = np.nonzero(anyb & (first > 0))[0]
    if ref.size:

        def make_fn(rows):
            r = ref[rows]
            plan_r = _plan(law, batch.view(ids[r], column=True))
            p_r = _take_params(p, ids[r], column=True)

            def fn(tt):
                f, _ = plan_r.force(p_r, tt[:, None], ys[:, r, None], tiny[r, None])
                return hold[r] * f[:, 0] - np.abs(need[r])

            return fn

        lo = grid[ref, first[ref] - 1]
        hi = grid[ref, first[ref]]
        tb[ref] = _root(make_fn, lo, hi, 1e-15 * np.maximum(t_end[ref], 1e-300), 0.0, mg[ref, first[ref] - 1],
                        mg[ref, first[ref]])
    return tb, hold, need


def _fill_stuck(law, batch, ids, ts, ys, t_from, t_to, T, Y, done, stuck_mask, block=256, fast=None):
    """Stuck-phase states (``solvers.stick.stuck_states``) at outputs in [t_from, t_to] not yet filled; per
    scene on its whole grid row, ``block`` scenes at a time (working memory bounded, not per output point;
    256 scenes of 101 outputs cost a third less per scene than 2,048, their arrays staying in cache). With
    ``fast`` (numba there) the selection and writing are one compiled pass (``compiled.scatter_stuck``)."""
    assert all(y.flags.c_contiguous for y in Y) and done.flags.c_contiguous  # written through flat views
    m = T.shape[1]
    for b in range(0, ids.size, block):
        bi = slice(b, b + block)
        rows = ids[bi]
        Ts = T[rows]
        if fast is not None:
            plan = _plan(law, batch.view(rows, column=True))
            Ys, _ = stick.stuck_states(plan, Ts, ts[bi, None], ys[:, bi, None])
            compiled.scatter_stuck(Ys, rows, Ts, t_from[bi], t_to[bi], done, stuck_mask, Y)
            continue
        sel = (Ts >= t_from[bi, None]) & (Ts <= t_to[bi, None]) & ~done[rows]
        r, c = np.nonzero(sel)
        if r.size == 0:
            continue
        plan = _plan(law, batch.view(rows, column=True))  # per scene, broadcast along its times
        Ys, _ = stick.stuck_states(plan, Ts, ts[bi, None], ys[:, bi, None])
        flat = rows[r] * m + c
        src = r * m + c
        for j in range(Y.shape[0]):  # integer take and put per state: several times faster than 2-d fancy indexing
            np.put(Y[j], flat, np.take(Ys[j], src))
        done.reshape(-1)[flat] = True
        stuck_mask.reshape(-1)[flat] = True


# --- the vectorized Runge-Kutta path ----------------------------------------------------------
def _run_rk(law, batch, p, T, method, rtol, atol, into=None):
    nsc, m = T.shape
    full = _plan(law, batch.view())
    d = len(full.states)
    t_end = T[:, -1].copy()
    scale = np.broadcast_to(state_scales(full, t_end), (d, nsc))
    Y = None  # states on the output grid; the first sliding phase's own array when every scene slides
    done = np.zeros((nsc, m), dtype=bool)
    stuck_mask = np.zeros((nsc, m), dtype=bool)
    stick_time = np.full(nsc, np.nan)
    segments = np.zeros(nsc, dtype=int)
    nfev = np.zeros(nsc, dtype=np.int64)
    iterations = 0
    y0 = np.broadcast_to(full.initial_state().reshape(d, -1), (d, nsc)).copy()
    u_start = np.broadcast_to(full.rigid_slip(y0), (nsc,))
    direction = np.sign(u_start)
    t0 = np.zeros(nsc)
    # scenes starting at zero slip begin stuck (they may break away at once)
    slide_ids = np.nonzero(direction != 0)[0]
    stuck_ids = np.nonzero(direction == 0)[0]
    last_dir = np.zeros(nsc)
    fast = compiled.prepare(law, full, p, nsc)  # the compiled sliding phases, where they serve this batch
    while slide_ids.size or stuck_ids.size:
        if stuck_ids.size:
            segments[stuck_ids] += 1
            tb, hold, need = _breakaway(law, batch, p, stuck_ids, t0[stuck_ids], y0[:, stuck_ids], t_end[stuck_ids],
                                        last_dir[stuck_ids])
            end = np.where(np.isnan(tb), t_end[stuck_ids], tb)
            held = ~(tb == t0[stuck_ids])  # breakaway at once: the sliding phase owns the outputs at t0
            if Y is None:
                Y = np.full((d, nsc, m), np.nan) if into is None else into["states"]
                Y.fill(np.nan)
            if held.any():
                h_ids = stuck_ids[held]
                _fill_stuck(law, batch, h_ids, t0[h_ids], y0[:, h_ids], t0[h_ids], end[held], T, Y, done, stuck_mask,
                            fast=fast)
            go = ~np.isnan(tb) & (tb < t_end[stuck_ids])
            ids = stuck_ids[go]
            if ids.size:
                plan_s = _plan(law, batch.view(ids, column=True))
                ys, _ = stick.stuck_states(plan_s, tb[go][:, None], t0[ids][:, None], y0[:, ids][:, :, None])
                y0[:, ids] = ys[:, :, 0]
                t0[ids] = tb[go]
                direction[ids] = hold[go]
            slide_ids = np.union1d(slide_ids, ids)
            stuck_ids = np.array([], dtype=int)
        if slide_ids.size == 0:
            break
        segments[slide_ids] += 1
        if np.any(segments > MAX_SEGMENTS):
            i = int(np.argmax(segments > MAX_SEGMENTS))
            raise SolverError(f"batch {method}: slip changed between sliding and sticking more than {MAX_SEGMENTS} times "
                              f"in scene {i} (chatter); the law is not suited to this scene")
        first_all = Y is None and slide_ids.size == nsc and into is not None  # integrated straight into the result
        res = _slide_rk(law, batch, p, slide_ids, t0, y0, direction, T, t_end, scale, method, rtol, atol,
                        into["states"] if first_all else None, fast)
        iterations += res.iterations
        nfev[slide_ids] += res.nfev
        new = res.reached & ~done[slide_ids]
        if Y is None:  # the first phase and every scene slides: its outputs (NaN where not reached) are Y
            Y = res.Y
            if res.scaled:
                Y *= scale[:, :, None]
            done |= new
        elif slide_ids.size == nsc:  # every scene slides: no gathering
            np.copyto(Y, res.Y * scale[:, :, None] if res.scaled else res.Y, where=new[None])
            done |= new
        else:
            r, c = np.nonzero(new)
            Y[:, slide_ids[r], c] = res.Y[:, r, c] * scale[:, slide_ids[r]] if res.scaled else res.Y[:, r, c]
            done[slide_ids[r], c] = True
        ev = np.nonzero(~np.isnan(res.t_event))[0]
        ids = slide_ids[ev]
        ts = res.t_event[ev] * t_end[ids]
        first = np.isnan(stick_time[ids])
        stick_time[ids[first]] = ts[first]
        plan_e = _plan(law, batch.view(ids))
        y0[:, ids] = _zero_slip(plan_e, res.y_event[:, ev] * scale[:, ids])
        t0[ids] = ts
        last_dir[ids] = direction[ids]
        stuck_ids = ids[ts < t_end[ids]]
        slide_ids = np.array([], dtype=int)
    if not done.all():
        i = int(np.argmax(~done.all(axis=1)))
        raise SolverError(f"batch {method}: scene {i} ended before its last requested time")
    need = stick.needed_force(_plan(law, batch.view(column=True)))
    out = _finish(law, batch, p, T, Y, ~stuck_mask, need, into)
    out["stick_time"] = stick_time
    return out, {"nfev": int(nfev.sum()), "nfev_per_scene": nfev, "iterations": iterations,
                 "segments": int(segments.max(initial=0)), "method": method,
                 "engine": "numpy" if fast is None else "compiled"}


def _slide_rk(law, batch, p, ids, t0, y0, direction, T, t_end, scale, method, rtol, atol, out=None, fast=None):
    """One sliding phase for scenes ``ids`` on the scaled problem (time / span, states / scale); with
    ``fast`` (``compiled.prepare``) by the compiled kernel, else by ``vecrk.integrate``: the same steps."""
    span = t_end[ids]
    if fast is not None:
        return fast.integrate(ids, t0, y0, direction, t_end, scale, T, method, rtol, atol, out)
    sc = scale[:, ids]

    def make_rhs(k):
        g_ids = ids[k]
        plan = _plan(law, batch.view(g_ids))
        pv = _take_params(p, g_ids)
        tsc, ssc = span[k], sc[:, k]
        fac = tsc / ssc
        dirs = direction[g_ids]

        def rhs(s, z):
            dy = plan.derivatives(pv, s * tsc, z * ssc, dirs)
            dy *= fac  # a fresh array: scaled in place
            return dy

        return rhs

    def make_event(k):
        g_ids = ids[k]
        plan = _plan(law, batch.view(g_ids))
        dsc = direction[g_ids] / sc[0, k]

        def g(s, z):
            return plan.rigid_slip(z * sc[:, k]) * dsc

        return g

    return vecrk.integrate(make_rhs, t0[ids] / span, y0[:, ids] / sc, 1.0, _scaled_grid(T, ids, span), method=method,
                           rtol=rtol, atol=atol, make_event=make_event, breaks=_breaks(batch, ids, span), out=out)


def _scaled_grid(T, ids, span):
    """Output times of scenes ids in units of their spans: one (m,) grid when they share it, else (k, m).

    The default grid, m points over each scene's span, is one grid in scaled time: its rows are taken as
    exactly linspace(0, 1, m), row by row (so a scene's outputs do not depend on its batch or chunk)."""
    m = T.shape[1]
    if T.strides[0] == 0 and np.all(span == span[0]):  # one grid and one span for all
        return T[0] / span[0]
    Tid = T if ids.size == T.shape[0] else T[ids]  # ids are sorted: all of them is every row in order
    rel = np.linspace(0.0, 1.0, m)
    on = np.all(Tid == span[:, None] * rel, axis=1)
    if on.all():
        return rel
    s_out = Tid / span[:, None]
    s_out[on] = rel
    return s_out


def _breaks(batch, ids, span):
    """End of contact of half-sine area and normal-force models, in units of each scene's span."""
    view = batch.view(ids)
    cols = [np.broadcast_to(np.asarray(m.contact_time, dtype=float), ids.shape) / span
            for m in (view.area, view.normal) if hasattr(m, "contact_time")]
    return np.column_stack(cols) if cols else None


# --- the vectorized closed forms -------------------------------------------------------------
def _run_exact(law, batch, p, T, into=None):
    nsc, m = T.shape
    view = batch.view(column=True)
    plan = _plan(law, view)
    pc = _take_params(p, slice(None), column=True)
    form = law.form(pc)
    d = len(plan.states)
    y0 = np.broadcast_to(plan.initial_state().reshape(d, -1, 1), (d, nsc, 1))
    stick_time = np.full(nsc, np.nan)
    stuck_mask = np.zeros((nsc, m), dtype=bool)
    fallback = np.zeros(nsc, dtype=bool)
    dirs, info = None, {}
    if isinstance(form, exact.AreaSlipForm):
        J, K = exact._area_slip(plan, form.k, 0.0, y0, T)
        Y = exact._states(plan, 0.0, y0, T, J, K, out=None if into is None else into["states"])
    else:
        u_s = np.broadcast_to(plan.rigid_slip(y0), (nsc, 1))
        sgn = np.sign(u_s)
        fallback |= sgn[:, 0] == 0
        sgn = np.where(sgn == 0, 1.0, sgn)
        ts = _exact_stop(law, batch, p, None, plan, form, 0.0, y0, u_s[:, 0], sgn[:, 0], T[:, -1])
        hit = ~np.isnan(ts) & ~fallback
        segs, tb_first = np.where(hit, 2, 1), np.full(nsc, np.nan)  # phases per scene, first breakaway time [s]
        info = {"segments_per_scene": segs, "breakaway_time": tb_first}
        tcol = np.where(hit, ts, np.inf)[:, None]
        # the sliding closed form at min(t, stick time): frozen at the stick, where the stuck phase continues
        tt = np.minimum(T, tcol) if hit.any() else T
        signed = exact.NormalAreaRateForm(a=sgn * form.a, c=sgn * form.c)  # the slip's sign in the form: no pass
        J1, K1, _ = exact._normal_area_rate(plan, signed, 0.0, y0, 1.0, tt, find_stop=False)
        Y = exact._states(plan, 0.0, y0, tt, J1, K1, out=None if into is None else into["states"])
        if hit.any():
            stick_time[hit] = ts[hit]
            ids = np.nonzero(hit)[0]
            ys = _zero_slip(_plan(law, batch.view(ids)), Y[:, ids, -1])  # the state at the stick, slip exactly zero
            stuck_mask = T > tcol
            v_stick = np.zeros((nsc, 1))
            v_stick[ids, 0] = ys[0]
            np.copyto(Y[0], v_stick, where=stuck_mask)  # zero slip exactly while stuck, as the stick state has it
            stick.stuck_states(plan, T, tt, Y, out=Y)  # dt = 0 before the stick: those states stay
            dirs = _exact_phases(law, batch, p, T, Y, stuck_mask, ids, ts[ids], ys, sgn[ids, 0], segs, tb_first)
    need = stick.needed_force(plan)
    out = _finish(law, batch, p, T, np.nan_to_num(Y, copy=into is None) if fallback.any() else Y, ~stuck_mask, need, into,
                  dirs)
    for i in np.nonzero(fallback)[0]:
        _scalar_into(out, stick_time, law, batch, p, T, i, info)
    out["stick_time"] = stick_time
    return out, info | {"nfev": 0, "scalar_fallback": int(fallback.sum())}


def _exact_phases(law, batch, p, T, Y, stuck_mask, ids, ts, ys, last_dir, segs, tb_first):
    """After the first stick of scenes ``ids`` (at ts [s] in state ys (d, k), slip before of sign last_dir):
    breakaway, a sliding phase in closed form from there, perhaps a stick again, and so on, as
    ``solvers.segments.run`` sequences them, with only the scenes still going in each round. A phase owns
    its outputs in (start, end]; they are written into Y and stuck_mask, each scene's number of phases into
    segs and its first breakaway time into tb_first. Returns the slip direction of the outputs of the
    later sliding phases ((n, m), 0 elsewhere; None if no scene broke away)."""
    dirs = None
    while ids.size:
        t_end = T[ids, -1]
        tb, hold, _ = _breakaway(law, batch, p, ids, ts, ys, t_end, last_dir)
        go = ~np.isnan(tb) & (tb < t_end)
        if not go.any():
            break
        ids, ts, ys, tb, hold, t_end = ids[go], ts[go], ys[:, go], tb[go], hold[go], t_end[go]
        tb_first[ids] = np.where(np.isnan(tb_first[ids]), tb, tb_first[ids])
        segs[ids] += 2
        if np.any(segs[ids] > MAX_SEGMENTS):
            i = int(ids[np.argmax(segs[ids] > MAX_SEGMENTS)])
            raise SolverError(f"batch exact: slip changed between sliding and sticking more than {MAX_SEGMENTS} "
                              f"times in scene {i} (chatter); the law is not suited to this scene")
        plan = _plan(law, batch.view(ids, column=True))
        form = law.form(_take_params(p, ids, column=True))
        t0, h = tb[:, None], hold[:, None]
        y0 = stick.stuck_states(plan, t0, ts[:, None], ys[:, :, None])[0]  # (d, k, 1): the state at breakaway
        u_s = np.broadcast_to(plan.rigid_slip(y0), (ids.size, 1))[:, 0]
        t_stop = _exact_stop(law, batch, p, ids, plan, form, tb, y0, u_s, hold, t_end)
        stops = ~np.isnan(t_stop)
        end = np.where(stops, t_stop, np.inf)[:, None]
        signed = exact.NormalAreaRateForm(a=h * form.a, c=h * form.c)

        def states(tt):
            J, K, _ = exact._normal_area_rate(plan, signed, t0, y0, 1.0, tt, find_stop=False)
            return exact._states(plan, t0, y0, tt, J, K)

        Tr = T[ids]
        Ys = states(np.clip(Tr, t0, end))
        te = np.where(stops, t_stop, tb)[:, None]
        y_stop = _zero_slip(plan, states(te))  # the state at the stop, slip exactly zero (d, k, 1)
        after, slide = Tr > t0, Tr <= end
        if stops.any():
            Ys = np.where(slide, Ys, stick.stuck_states(plan, Tr, te, y_stop)[0])
        Y[:, ids] = np.where(after, Ys, Y[:, ids])
        stuck_mask[ids] = np.where(after, ~slide, stuck_mask[ids])
        if dirs is None:
            dirs = np.zeros(T.shape)
        dirs[ids] = np.where(after & slide, h, dirs[ids])
        segs[ids[~stops]] -= 1  # slid to the end: no stuck phase after it
        ids, ts, ys, last_dir = ids[stops], t_stop[stops], y_stop[:, stops, 0], hold[stops]
    return dirs


def _known_capacity(law, plan, pc, k, ts, need):
    """Breakaway times without a scan, when the law's form makes them obvious, else None.

    Under F = s (a N + c dA/dt) the holding capacity is a N + c dA/dt. With c = 0, a >= 0 and a
    normal-force model that is never negative, the capacity a N >= 0 holds a scene that needs no
    force (no drive: the rolling sphere) for ever, and a constant N needs one comparison.
    """
    form = law.form(pc)
    if not isinstance(form, exact.NormalAreaRateForm) or not isinstance(plan.scene.normal, _NONNEGATIVE_N):
        return None
    if not (np.all(np.asarray(form.c) == 0.0) and np.all(np.asarray(form.a) >= 0.0)):
        return None
    if np.all(need == 0.0):
        return np.full(k, np.nan)
    if isinstance(plan.scene.normal, WeightNormal):
        cap = np.broadcast_to(form.a * plan.scene.normal.value, (k, 1))[:, 0]
        return np.where(cap < np.abs(need), ts, np.nan)
    return None


def _exact_stop(law, batch, p, ids, plan, form, t0, y0, u_s, sgn, t_end):
    """First time after t0 each scene's slip reaches zero under F = s (a N + c dA/dt), NaN if not before t_end.

    ids: the batch's scenes these rows are (None: all, plan and form theirs); t0: 0.0 (first contact) or
    per row [s], a restart from rest: there, as in ``exact._normal_area_rate``, slip must pass zero by
    SLIP_MARGIN of its scale to count (round-off an ulp after t0 is not a stop), and the stop is the zero
    of slip after the last scanned time at which slip was strictly of the phase's sign."""
    k = t_end.shape[0]
    restart = np.ndim(t0) > 0
    t0c = t0[:, None] if restart else 0.0

    def make_g(rows):  # sgn * slip at times tt (k, q) for rows (None: all)
        sub = plan if rows is None else _plan(law, batch.view(rows if ids is None else ids[rows], column=True))
        f = form if rows is None else law.form(_take_params(p, rows if ids is None else ids[rows], column=True))
        s, us, y0s, t0s = ((sgn[:, None], u_s[:, None], y0, t0c) if rows is None else
                           (sgn[rows, None], u_s[rows, None], y0[:, rows], t0c[rows] if restart else t0c))

        def g(tt):
            J1 = exact._normal_area_rate(sub, f, t0s, y0s, 1.0, tt, find_stop=False)[0]
            return s * (us + sub.drive * (tt - t0s)) - sub.kappa * J1

        return g

    offset = np.zeros(k)
    noise = 8 * np.finfo(float).eps * np.abs(u_s)  # slip is u_s minus terms of its size
    c_zero = np.all(np.asarray(form.c) == 0.0)
    monotone = not restart and c_zero and (isinstance(batch.template.normal, exact.WeightNormal)
                                           or np.all(sgn * np.broadcast_to(plan.drive, (k, 1))[:, 0] <= 0.0))
    if monotone:
        g_end = make_g(None)(t_end[:, None])[:, 0]
        rows = np.nonzero(g_end <= 0.0)[0]
        lo, hi = np.zeros(rows.size), t_end[rows]
        glo = ghi = None
    else:
        frac = np.linspace(0.0, 1.0, SCAN)[None, :]
        grid = t0c + (t_end - t0)[:, None] * frac if restart else t_end[:, None] * frac
        gg = make_g(None)(grid)
        if restart:
            sc = plan.scene
            terms = (sc.u0, plan.drive * t_end[:, None], sc.omega0 * (0.0 if sc.radius is None else sc.radius))
            scale = np.maximum.reduce([np.broadcast_to(np.abs(np.asarray(x, dtype=float)), (k, 1))[:, 0] for x in terms])
            margin = exact.SLIP_MARGIN * np.maximum(scale, 1e-300)
            noise = 8 * np.finfo(float).eps * scale
        else:
            margin = np.zeros(k)
        bad = gg[:, 1:] + margin[:, None] <= 0.0
        rows = np.nonzero(bad.any(axis=1))[0]
        ihi = np.argmax(bad[rows], axis=1) + 1
        if restart and rows.size:  # the zero of slip after the last time it was of the phase's sign, if any
            ahead = (gg[rows] > 0.0) & (np.arange(SCAN)[None, :] < ihi[:, None])
            has = ahead.any(axis=1)
            ihi = np.where(has, SCAN - np.argmax(ahead[:, ::-1], axis=1), ihi)
            offset[rows] = np.where(has, 0.0, margin[rows])
        lo, hi = grid[rows, ihi - 1], grid[rows, ihi]
        glo, ghi = gg[rows, ihi - 1] + offset[rows], gg[rows, ihi] + offset[rows]  # fn at the bracket, from the scan
    ts = np.full(k, np.nan)
    if rows.size and monotone and exact.closed_stop_applies(plan, form, 0.0):
        ts[rows] = np.minimum(np.broadcast_to(exact.half_sine_stop(plan, form, u_s[:, None]), (k, 1))[rows, 0],
                              t_end[rows])
        ts[rows[ts[rows] >= t_end[rows]]] = np.nan
    elif rows.size:
        def make_fn(r):
            g, o = make_g(rows[r]), offset[rows[r]]
            return lambda x: g(x[:, None])[:, 0] + o

        ts[rows] = _root(make_fn, lo, hi, 1e-15 * np.maximum(t_end[rows], 1e-300), noise[rows], glo, ghi)
        ts[rows[ts[rows] >= t_end[rows]]] = np.nan
    return ts



def _scalar_into(out, stick_time, law, batch, p, T, i, info):
    """Re-run scene i with the scalar exact solver (it starts at zero slip)."""
    from .solvers import simulate

    pi = {k: v if isinstance(v, float) else float(v[i]) for k, v in p.items()}
    tr = simulate(law, batch.scene(i), pi, solver="exact", t=T[i])
    for k in ("u", "v", "omega", "theta", "force", "A", "N"):
        if out.get(k) is not None and getattr(tr, k) is not None:
            out[k][i] = getattr(tr, k)
    stick_time[i] = np.nan if tr.stick_time is None else tr.stick_time
    if "segments_per_scene" in info:
        info["segments_per_scene"][i] = tr.info["segments"]
