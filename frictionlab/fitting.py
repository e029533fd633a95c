"""Fit a friction law to one or more datasets with lmfit.

``fit(law, datasets, solver='auto', ...)`` returns a ``FitResult``; it never raises for a
fit that fails (solver error, NaN from the law, no convergence): the result then has
``status = 'failed'`` and a ``reason``. Bad *input* (unknown law, parameter or scene
quantity) raises a one-line FrictionLabError.

* Parameters come from the law's ParamSpecs; the optimizer sees value / spec.scale, so
  lam ~ 1e6 Pa s/m and h ~ 1e-6 m are both order one. A dataset's ``[fixed]`` values are held.
* Scene quantities can be freed by name with bounds (``free={'u0': (8, 14)}``, SI units);
  they are always per dataset.
* Residuals are (model - data) / sigma, sigma the dataset's noise estimate, so datasets in
  different units fit together. With several datasets, law parameters are shared (a global
  fit) unless named in ``local``.
* Predictions go through ``predict``; a dataset kind plugs in with ``register_predictor``.
"""
from __future__ import annotations

import math
import re
import time
import warnings
from collections.abc import Callable, Mapping, Sequence

import attrs
import numpy as np

from .dataset import Dataset, load_dataset
from .errors import DatasetError, FrictionLabError, ParameterError, SolverError
from .law import FrictionLaw
from .registry import get_law
from .scene import Scene

#: Trajectory series that a time-series observable reads.
SERIES = {"omega": "omega", "theta": "theta", "v": "v", "u": "u"}

#: Scene quantities that can be freed, with their SI unit (dotted names reach into sub-models).
SCENE_QUANTITIES = {
    "u0": "m/s", "omega0": "rad/s", "mass": "kg", "radius": "m", "incline": "rad",
    "area.peak": "m^2", "area.contact_time": "s", "area.area": "m^2", "area.initial": "m^2", "area.rate": "m^2/m",
    "normal.impulse": "N*s", "normal.contact_time": "s", "normal.value": "N", "normal.coefficient": "N/m^3",
    "compliance.stiffness": "N/m", "compliance.damping": "N*s/m",
}

CORRELATION_LIMIT = 0.95
PENALTY = 1e4  # weighted residual per point when the model cannot be evaluated
FIT_RTOL = 1e-10  # ODE tolerance during fits: finite-difference Jacobians need a smooth model
ODE_STARTS = 2  # at most this many starts are refined when a dataset needs the (costlier) ODE solver
FTOL = 1e-6  # relative chi-square and step tolerances of Levenberg-Marquardt


class SkipDataset(FrictionLabError):
    """A dataset this law or solver cannot predict (reported as 'skipped', not 'failed')."""


# --- targets: what is fitted -------------------------------------------------------------
@attrs.frozen(eq=False)
class Target:
    """One fitted series: the dataset, the observable, its values y and 1-sigma per point (SI)."""

    dataset: Dataset
    observable: str
    y: np.ndarray
    sigma: np.ndarray
    derivation: str = ""  # "" or how y was derived (e.g. omega from theta by poly9)

    @property
    def name(self) -> str:
        return self.dataset.name

    @property
    def t(self) -> np.ndarray | None:
        return self.dataset.columns.get("t")

    @property
    def label(self) -> str:
        return f"{self.name} ({self.observable}{', ' + self.derivation if self.derivation else ''})"


def make_target(dataset, observable: str | None = None, derive: str | None = None) -> Target:
    """The series to fit from ``dataset``: its observable, another column, or omega derived from theta.

    derive: None, 'poly9' or 'spline' (then observable is omega, computed from the theta column).
    """
    ds = load_dataset(dataset)
    if ds.kind == "contact-area":
        raise SkipDataset(f"dataset '{ds.name}' is a contact-area series: supporting data, not fitted")
    obs = observable or ds.observable
    if derive:
        from .derive import derive_omega

        if "theta" not in ds.columns:
            raise DatasetError(f"dataset '{ds.name}': deriving omega needs a 'theta' column")
        d = derive_omega(ds.t, ds.columns["theta"], derive, ds.noise.get("theta"))
        return Target(ds, "omega", d.omega, d.sigma, f"omega from theta by {derive}")
    if obs not in ds.columns:
        raise DatasetError(f"dataset '{ds.name}': no column '{obs}' to fit (has: {', '.join(ds.columns)})")
    if obs in ds.noise:
        sigma = np.full(len(ds), ds.noise[obs])
    else:
        raise DatasetError(f"dataset '{ds.name}': [noise] gives no estimate for '{obs}'; add e.g. {obs} = '...'")
    return Target(ds, obs, ds.columns[obs], sigma)


# --- predictions: one function per dataset kind -------------------------------------------
Predictor = Callable[[FrictionLaw, Target, Scene, Mapping[str, float], str], np.ndarray]
PREDICTORS: dict[str, Predictor] = {}


def register_predictor(kind: str, fn: Predictor) -> None:
    """Make dataset ``kind`` fittable: fn(law, target, scene, params, solver) -> model of target.y (SI)."""
    PREDICTORS[kind] = fn


def _predict_series(law, target, scene, params, solver):
    from .solvers import simulate

    if target.observable not in SERIES:
        raise SkipDataset(f"dataset '{target.name}': observable '{target.observable}' is not a simulated series "
                          f"({', '.join(SERIES)})")
    tr = simulate(law, scene, params, solver=solver, t=target.t, rtol=FIT_RTOL)
    return tr[SERIES[target.observable]]


register_predictor("impact", _predict_series)
register_predictor("incline", _predict_series)


def predict(law, target: Target, params: Mapping[str, float], solver: str = "exact",
            scene: Scene | None = None) -> np.ndarray:
    """The law's prediction of ``target.y`` (SI) for law parameters ``params`` (SI), on ``scene``
    (default: the dataset's). Raises SkipDataset for a kind nobody can predict yet."""
    law = get_law(law)
    kind = target.dataset.kind
    if kind not in PREDICTORS:
        raise SkipDataset(f"no predictor for dataset kind '{kind}' (dataset '{target.name}'); "
                          f"known: {', '.join(PREDICTORS)}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # series accuracy warnings are recorded in the result instead
        return np.asarray(PREDICTORS[kind](law, target, scene or target.dataset.scene, params, solver), dtype=float)


def applicable_solvers(law, scene: Scene) -> dict[str, str | None]:
    """For 'exact', 'series' and 'ode': None if it applies to ``law`` on ``scene``, else why not."""
    from .plan import make_plan
    from .solvers import exact, series

    law = get_law(law)
    try:
        plan = make_plan(scene, law)
    except FrictionLabError as exc:
        return {name: str(exc) for name in ("exact", "series", "ode")}
    out = {"ode": None}
    for name, module in (("exact", exact), ("series", series)):
        try:
            for p in (law.defaults(), _generic_params(law)):  # forms may degenerate at defaults (eta' = 0)
                module.check(plan, p)
            out[name] = None
        except FrictionLabError as exc:
            out[name] = str(exc)
    return out


def _generic_params(law) -> dict[str, float]:
    p = {}
    for s in law.params:
        v = s.default + s.scale
        p[s.name] = v if v <= s.upper else s.default - s.scale
    return p


def auto_solver(law, scene: Scene) -> str:
    """'exact' where a closed form exists for this law and scene, else 'ode'."""
    return "exact" if applicable_solvers(law, scene)["exact"] is None else "ode"


def set_scene_quantity(scene: Scene, name: str, value: float) -> Scene:
    """A copy of ``scene`` with the (dotted) quantity ``name`` set to ``value`` (SI)."""
    head, _, tail = name.partition(".")
    if not tail:
        return attrs.evolve(scene, **{head: float(value)})
    sub = getattr(scene, head)
    return attrs.evolve(scene, **{head: attrs.evolve(sub, **{tail: float(value)})})


def get_scene_quantity(scene: Scene, name: str) -> float:
    if name not in SCENE_QUANTITIES:
        raise ParameterError(f"scene quantity '{name}' cannot be freed; choose from {', '.join(SCENE_QUANTITIES)}")
    obj = scene
    for part in name.split("."):
        if obj is None or not hasattr(obj, part):
            raise ParameterError(f"scene quantity '{name}': this scene has no {part!r}"
                                 + (f" ({type(obj).__name__})" if obj is not None else ""))
        obj = getattr(obj, part)
    if not isinstance(obj, (int, float)):
        raise ParameterError(f"scene quantity '{name}' is not a number on this scene")
    return float(obj)


# --- results -------------------------------------------------------------------------------
@attrs.frozen
class ParamResult:
    """A fitted (or held) parameter: SI value and standard error, unit, bounds and role."""

    name: str  # display name: 'lam', or 'u0[impact-golf-v28]' for a per-dataset quantity
    key: str  # law parameter or scene quantity
    kind: str  # 'law' | 'scene'
    value: float
    stderr: float | None
    unit: str
    vary: bool
    initial: float
    lower: float
    upper: float
    datasets: tuple[str, ...]
    fixed_by: str = ""  # why it is held: '' when fitted


@attrs.frozen
class Stats:
    """Fit statistics. chisqr uses noise-weighted residuals; rss and rmse are in the observable's
    SI unit (single-dataset fits only, else nan). n_params counts identifiable directions."""

    n_points: int
    n_params: int
    n_free: int
    chisqr: float
    redchi: float
    rss: float
    rmse: float
    aic: float
    aicc: float
    bic: float


@attrs.frozen
class Identifiability:
    verdict: str
    warnings: tuple[str, ...] = ()
    at_bounds: tuple[str, ...] = ()
    missing_stderr: dict = attrs.field(factory=dict)  # name -> reason
    high_correlations: tuple[tuple[str, str, float], ...] = ()
    ratio_only: tuple[tuple[str, str], ...] = ()
    no_effect: tuple[str, ...] = ()


@attrs.frozen(eq=False)
class DatasetFit:
    """One dataset's part of a fit: data, best model, residuals (SI) and what produced them."""

    target: Target
    solver: str
    params: dict  # law parameters at the best fit (SI)
    scene: Scene
    model: np.ndarray
    rss: float
    rmse: float
    chisqr: float

    @property
    def name(self) -> str:
        return self.target.name

    @property
    def residual(self) -> np.ndarray:
        return self.model - self.target.y

    def trajectory(self, law, t=None, n: int = 401):
        """The best-fit trajectory on times t (default: n points over the scene), or None for
        kinds without a time series."""
        from .solvers import simulate

        if self.target.t is None:
            return None
        if t is None:
            t = np.linspace(0.0, max(self.scene.duration, float(self.target.t[-1])), n)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return simulate(law, self.scene, self.params, solver=self.solver, t=t)


@attrs.frozen(eq=False)
class FitResult:
    """Outcome of ``fit``: parameters with errors, statistics, identifiability, per-dataset fits."""

    law: str
    solver: str
    datasets: tuple[str, ...]
    status: str  # 'ok' | 'failed' | 'skipped'
    reason: str = ""
    params: dict = attrs.field(factory=dict)  # display name -> ParamResult
    correlations: dict = attrs.field(factory=dict)  # (a, b) -> r, free parameters only
    stats: Stats | None = None
    identifiability: Identifiability | None = None
    per_dataset: tuple[DatasetFit, ...] = ()
    nfev: int = 0
    wall_time: float = 0.0
    message: str = ""
    notes: tuple[str, ...] = ()

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    def value(self, name: str) -> float:
        return self.params[name].value

    def stderr(self, name: str) -> float | None:
        return self.params[name].stderr

    def summary(self) -> str:
        """A few lines for the terminal."""
        on = ", ".join(d.target.label for d in self.per_dataset) if self.per_dataset else ", ".join(self.datasets)
        head = f"{self.law} [{self.solver}] on {on}: {self.status}"
        if not self.ok:
            return f"{head}: {self.reason}"
        s = self.stats
        lines = [head, f"  chi2 = {s.chisqr:.5g}, reduced chi2 = {s.redchi:.4g}, AIC = {s.aic:.5g}, "
                       f"BIC = {s.bic:.5g}, n = {s.n_points}, k = {s.n_params}, nfev = {self.nfev}, "
                       f"{self.wall_time:.2f} s"]
        for p in self.params.values():
            err = "held" if not p.vary and p.kind != "derived" else ("no error bar" if p.stderr is None else f"+/- {p.stderr:.3g}")
            why = f" ({p.fixed_by})" if p.fixed_by else ""
            lines.append(f"  {p.name:<28} = {p.value:.6g} {p.unit} {err}{why}")
        for w in self.identifiability.warnings:
            lines.append(f"  warning: {w}")
        for n in self.notes:
            lines.append(f"  note: {n}")
        return "\n".join(lines)


# --- the fit ---------------------------------------------------------------------------------
@attrs.frozen
class _Slot:
    pname: str  # lmfit identifier
    display: str
    kind: str
    key: str
    targets: tuple[int, ...]
    value: float  # SI start value
    lower: float
    upper: float
    scale: float
    unit: str
    vary: bool
    fixed_by: str = ""


def _ident(text: str) -> str:
    s = re.sub(r"\W", "_", text)
    return s if re.match(r"[A-Za-z_]", s) else f"p_{s}"


def _law_slots(law, targets, fixed, local, initial) -> list[_Slot]:
    slots = []
    multi = len(targets) > 1
    for spec in law.params:
        n = spec.name
        start = float(initial.get(n, spec.default))
        common = dict(kind="law", key=n, lower=spec.lower, upper=spec.upper, scale=spec.scale, unit=spec.unit)
        if n in fixed:
            slots.append(_Slot(_ident(n), n, targets=tuple(range(len(targets))), value=float(fixed[n]), vary=False,
                               fixed_by="held by the caller", **common))
            continue
        held = {i: float(t.dataset.fixed[n]) for i, t in enumerate(targets) if n in t.dataset.fixed}
        if not multi or (len(held) == len(targets) and len(set(held.values())) == 1):
            if held:
                slots.append(_Slot(_ident(n), n, targets=tuple(range(len(targets))), value=next(iter(held.values())),
                                   vary=False, fixed_by=f"[fixed] in dataset {targets[0].name}"
                                   if not multi else "[fixed] in every dataset", **common))
            else:
                slots.append(_Slot(_ident(n), n, targets=tuple(range(len(targets))), value=start, vary=True, **common))
            continue
        free = [i for i in range(len(targets)) if i not in held]
        for i, v in held.items():
            slots.append(_Slot(_ident(f"{n}__{i}"), f"{n}[{targets[i].name}]", targets=(i,), value=v, vary=False,
                               fixed_by=f"[fixed] in dataset {targets[i].name}", **common))
        if n in local:
            for i in free:
                slots.append(_Slot(_ident(f"{n}__{i}"), f"{n}[{targets[i].name}]", targets=(i,), value=start,
                                   vary=True, **common))
        elif free:
            slots.append(_Slot(_ident(n), n, targets=tuple(free), value=start, vary=True, **common))
    return slots


def _scene_slots(targets, free) -> list[_Slot]:
    slots = []
    for name, bounds in free.items():
        if not (isinstance(bounds, (tuple, list)) and len(bounds) in (2, 3)):
            raise ParameterError(f"free scene quantity '{name}': give (lower, upper) or (lower, upper, start) in SI")
        lo, hi = float(bounds[0]), float(bounds[1])
        if not lo < hi:
            raise ParameterError(f"free scene quantity '{name}': lower bound {lo:g} must be below upper {hi:g}")
        for i, tg in enumerate(targets):
            current = get_scene_quantity(tg.dataset.scene, name)
            start = float(bounds[2]) if len(bounds) == 3 else min(max(current, lo), hi)
            disp = name if len(targets) == 1 else f"{name}[{tg.name}]"
            slots.append(_Slot(_ident(f"scene_{name}__{i}"), disp, "scene", name, (i,), start, lo, hi,
                               max(abs(start), abs(lo), abs(hi), 1e-300) if start == 0 else abs(start),
                               SCENE_QUANTITIES[name], True))
    return slots


def _lmfit_bound(b: float, slot: _Slot) -> float:
    """Bounds far outside the parameter's scale are passed as infinite (the law still checks them)."""
    return b if abs(b) <= 1e4 * slot.scale else math.copysign(math.inf, b)


class _Model:
    """Evaluates the weighted residual for a vector of scaled parameter values."""

    def __init__(self, law, targets, solvers, slots):
        self.law, self.targets, self.solvers, self.slots = law, targets, solvers, slots
        self.failures = 0
        self.last_error = ""
        self.nfev = 0

    def split(self, values: Mapping[str, float]):
        """Per-target law parameters and scenes for SI slot values (by lmfit name)."""
        out = []
        for i, tg in enumerate(self.targets):
            p, scene = {}, tg.dataset.scene
            for s in self.slots:
                if i in s.targets:
                    if s.kind == "law":
                        p[s.key] = values[s.pname]
                    else:
                        scene = set_scene_quantity(scene, s.key, values[s.pname])
            out.append((p, scene))
        return out

    def models(self, values):
        return [predict(self.law, tg, p, solver, scene)
                for tg, solver, (p, scene) in zip(self.targets, self.solvers, self.split(values))]

    def residual(self, values) -> np.ndarray:
        self.nfev += 1
        out = []
        for tg, solver, (p, scene) in zip(self.targets, self.solvers, self.split(values)):
            try:
                m = predict(self.law, tg, p, solver, scene)
                if m.shape != tg.y.shape or not np.all(np.isfinite(m)):
                    raise SolverError(f"prediction for '{tg.name}' is not finite or has the wrong shape")
                out.append((m - tg.y) / tg.sigma)
            except SkipDataset:
                raise
            except FrictionLabError as exc:
                self.failures += 1
                self.last_error = str(exc)
                out.append(np.full(tg.y.shape, PENALTY))
        return np.concatenate(out)


def _si(params, slots) -> dict[str, float]:
    return {s.pname: params[s.pname].value * s.scale for s in slots}


def _start_grid(slots, rng, limit: int) -> list[dict[str, float]]:
    """Candidate starts in scaled units, the given start first: log-spaced multiples of the start
    for positive quantities, steps of the scale around it for signed ones, the bounds' span for
    scene quantities; clipped into the bounds. A full grid if it has at most ``limit`` points."""
    levels = max(3, min(15, int(round(limit ** (1.0 / len(slots))))))
    axes = []
    for s in slots:
        x0 = s.value / s.scale
        lo, hi = s.lower / s.scale, s.upper / s.scale
        if s.kind == "scene":
            c = np.linspace(lo, hi, levels)
        elif lo >= 0 and x0 > 0:
            c = x0 * np.logspace(-1.5, 1.5, levels)
        else:
            c = x0 + np.sinh(np.linspace(-4.0, 4.0, levels))  # dense near the start, out to +/- 27 scales
        axes.append(np.unique(np.clip(c, lo, hi)))
    start = [s.value / s.scale for s in slots]
    total = math.prod(len(a) for a in axes)
    if total <= limit:
        grid = np.array(np.meshgrid(*axes, indexing="ij")).reshape(len(axes), -1).T
    else:
        grid = np.array([[rng.choice(a) for a in axes] for _ in range(limit)])
    grid = np.vstack([start, grid])
    return [dict(zip((s.pname for s in slots), row)) for row in grid]


def _distinct(scored: list[tuple], n: int) -> list[dict]:
    """Up to n starts from (cost, order, candidate) sorted by cost: each differs from those taken by
    more than 10% in some coordinate and has a different cost (equal costs mean a plateau, such as
    a body stuck throughout, where a second start teaches nothing)."""
    out, costs = [], []
    for cost, _, c in scored:
        if any(abs(cost - k) <= 1e-9 * max(abs(cost), 1e-300) for k in costs):
            continue
        if all(any(abs(c[k] - o[k]) > 0.1 * max(abs(c[k]), abs(o[k]), 1e-3) for k in c) for o in out):
            out.append(c)
            costs.append(cost)
        if len(out) == n:
            break
    return out


def _search(lmfit, model: _Model, params, slots, solvers, scan: int, n_starts: int, max_nfev):
    """Score a grid of starts, refine the best distinct ones with Levenberg-Marquardt, keep the lowest
    chi-square. Returns (parameters, success, message)."""
    varying = [s for s in slots if s.vary]
    if not varying:
        return params, True, "nothing to fit: every parameter is held"
    starts = [{s.pname: params[s.pname].value for s in varying}]
    if scan:
        fixed_part = {s.pname: s.value / s.scale for s in slots if not s.vary}
        scored = []
        for cand in _start_grid(varying, np.random.default_rng(0), scan):
            vals = {**fixed_part, **cand}
            r = model.residual({s.pname: vals[s.pname] * s.scale for s in slots})
            scored.append((float(r @ r), len(scored), cand))
        scored.sort(key=lambda x: x[:2])  # ties keep grid order: the given start wins
        slow = any(x.startswith("ode") for x in solvers)
        starts = _distinct(scored, min(n_starts, ODE_STARTS) if slow else n_starts)
    best = None
    for start in starts:
        trial = params.copy()
        for k, v in start.items():
            trial[k].set(value=v)
        mini = lmfit.Minimizer(lambda ps: model.residual(_si(ps, slots)), trial, scale_covar=True,
                               max_nfev=max_nfev or 200 * (len(varying) + 1))
        r = mini.minimize(method="leastsq", epsfcn=1e-10, ftol=FTOL, xtol=FTOL)
        if best is None or (r.success, -r.chisqr) > (best.success, -best.chisqr):
            best = r
    return best.params, bool(best.success), str(best.message)


def fit(law, datasets, solver: str = "auto", *, free: Mapping[str, Sequence[float]] | None = None,
        fixed: Mapping[str, float] | None = None, local: Sequence[str] = (),
        initial: Mapping[str, float] | None = None, observable: str | None = None, derive: str | None = None,
        scan: int = 125, n_starts: int = 3, max_nfev: int | None = None) -> FitResult:
    """Fit ``law`` to one dataset or a group of them (a global fit) and return a FitResult.

    law: name or FrictionLaw. datasets: a Dataset, name, path or Target, or a list of them.
    solver: 'auto' (exact where a closed form exists, else ode), 'exact', 'series', 'ode[:METHOD]'.
    free: scene quantities to fit per dataset, name -> (lower, upper[, start]) in SI (see
    SCENE_QUANTITIES). fixed: law parameters held for every dataset (SI), on top of each
    dataset's [fixed]. local: law parameters fitted separately per dataset in a global fit.
    initial: start values (SI). observable / derive: what to fit (see make_target).
    scan: number of grid points scored before Levenberg-Marquardt (0: start from the defaults);
    n_starts: Levenberg-Marquardt runs from the best distinct grid points (the lowest chi2 wins);
    at most ODE_STARTS when a dataset is solved by 'ode' (deterministic, never timing-dependent).
    """
    import lmfit  # slow to import: only when fitting

    law = get_law(law)
    started = time.perf_counter()
    items = datasets if isinstance(datasets, (list, tuple)) else [datasets]
    if not items:
        raise DatasetError("fit: no datasets given")
    names = tuple(getattr(d, "name", str(d)) for d in items)

    def give_up(status, reason, **kw):
        return FitResult(law=law.name, solver=solver, datasets=names, status=status, reason=reason,
                         wall_time=time.perf_counter() - started, **kw)

    try:
        targets = [d if isinstance(d, Target) else make_target(d, observable, derive) for d in items]
    except SkipDataset as exc:
        return give_up("skipped", str(exc))
    names = tuple(t.name for t in targets)
    for name in list(fixed or {}) + list(local) + list(initial or {}):
        law.spec(name)  # unknown names are input errors
    solvers = []
    for tg in targets:
        if tg.dataset.kind not in PREDICTORS:
            return give_up("skipped", f"no predictor for dataset kind '{tg.dataset.kind}' (dataset '{tg.name}')")
        if tg.dataset.scene is None:
            return give_up("skipped", f"dataset '{tg.name}' has no scene")
        ok = applicable_solvers(law, tg.dataset.scene)
        s = auto_solver(law, tg.dataset.scene) if solver == "auto" else solver
        base = s.partition(":")[0]
        if base not in ok:
            from .solvers import parse_solver

            parse_solver(s)  # raises the one-line error for an unknown solver
        if ok.get(base):
            return give_up("skipped", f"{base} on '{tg.name}': {ok[base]}")
        solvers.append(s)
    slots = _law_slots(law, targets, dict(fixed or {}), set(local), dict(initial or {}))
    slots += _scene_slots(targets, dict(free or {}))
    model = _Model(law, targets, solvers, slots)
    params = lmfit.Parameters()
    for s in slots:
        params.add(s.pname, value=s.value / s.scale, vary=s.vary, min=_lmfit_bound(s.lower, s) / s.scale,
                   max=_lmfit_bound(s.upper, s) / s.scale)
    varying = [s for s in slots if s.vary]
    solver_label = solver if solver != "auto" else "+".join(dict.fromkeys(solvers))
    n_points = sum(t.y.size for t in targets)

    try:
        best_params, success, message = _search(lmfit, model, params, slots, solvers, scan, n_starts, max_nfev)
        values = _si(best_params, slots)
        models = model.models(values)
    except SkipDataset as exc:
        return give_up("skipped", str(exc))
    except FrictionLabError as exc:
        return give_up("failed", f"the model cannot be evaluated at the best parameters: {exc}", nfev=model.nfev)
    except Exception as exc:  # an optimizer or law crash is a failed fit, not a crashed comparison
        return give_up("failed", f"{type(exc).__name__}: {exc}", nfev=model.nfev)

    per = []
    for tg, solver_i, (p, scene), m in zip(targets, solvers, model.split(values), models):
        r = m - tg.y
        per.append(DatasetFit(tg, solver_i, p, scene, m, float(r @ r), float(np.sqrt(np.mean(r**2))),
                              float(np.sum((r / tg.sigma) ** 2))))
    chisqr = sum(d.chisqr for d in per)
    J = _jacobian(model, slots, values)
    structure = _structure(law, slots, values, J)
    stats = _stats(n_points, structure["k_eff"], len(varying), chisqr, per)
    status, reason = "ok", ""
    if not all(np.all(np.isfinite(d.model)) for d in per):
        status, reason = "failed", "the best-fit model is not finite"
    elif not success:
        status, reason = "failed", f"did not converge: {message}"
    elif model.failures and chisqr >= PENALTY**2:
        status, reason = "failed", f"the solver failed at every trial: {model.last_error}"
    notes = []
    if model.failures:
        notes.append(f"{model.failures} of {model.nfev} evaluations could not be solved and were penalized "
                     f"(last: {model.last_error})")
    notes += _series_notes(law, per)
    jac = _jacobian_errors(slots, values, J, structure, stats.redchi)
    presults = _param_results(slots, best_params, targets, structure, jac)
    correl = {}
    if structure["ratios"] or structure["no_effect"]:  # lmfit's covariance is degenerate: use the identifiable part
        correl = jac.get("correl", {})
    else:
        for s in varying:
            for other, r in (best_params[s.pname].correl or {}).items():
                o = next(x for x in slots if x.pname == other)
                if s.display < o.display:
                    correl[(s.display, o.display)] = float(r)
    ident = _verdict(structure, presults, correl)
    return FitResult(law=law.name, solver=solver_label, datasets=names, status=status, reason=reason,
                     params=presults, correlations=correl, stats=stats, identifiability=ident,
                     per_dataset=tuple(per), nfev=model.nfev, wall_time=time.perf_counter() - started,
                     message=message, notes=tuple(notes))


def _stats(n, k, k_free, chisqr, per) -> Stats:
    """AIC = n ln(chi2/n) + 2k (lmfit's convention: Gaussian errors, noise scale profiled out),
    AICc = AIC + 2k(k+1)/(n-k-1), BIC = n ln(chi2/n) + k ln n."""
    single = len(per) == 1
    chi = max(chisqr, np.finfo(float).tiny)
    ll = n * math.log(chi / n)
    aic = ll + 2 * k
    aicc = aic + (2 * k * (k + 1) / (n - k - 1) if n - k - 1 > 0 else math.inf)
    return Stats(n_points=n, n_params=k, n_free=k_free, chisqr=chisqr,
                 redchi=chisqr / (n - k) if n > k else math.inf,
                 rss=per[0].rss if single else math.nan, rmse=per[0].rmse if single else math.nan,
                 aic=aic, aicc=aicc, bic=ll + k * math.log(n))


def _series_notes(law, per) -> list[str]:
    from .solvers.series import B_ACCURATE

    notes = []
    for d in per:
        if d.solver == "series":
            form = law.form(d.params)
            s = d.scene
            b = form.k * s.area.peak * s.area.contact_time / (s.mass * math.pi)
            if b > B_ACCURATE:
                notes.append(f"series on '{d.name}' at b = {b:.3g}: the first-order expansion (eq 7) is accurate "
                             f"only for b << 1 (below about {B_ACCURATE})")
            if b > 0.5:
                t_rev = math.acos(-(1 - b) / b) * s.area.contact_time / math.pi
                notes.append(f"series on '{d.name}': with b = {b:.3g} > 0.5 the truncated slip u0 (1 - b + b cos phi t) "
                             f"changes sign at t = {t_rev * 1e6:.0f} us (u(t_c) = u0 (1 - 2b) < 0), so the series "
                             "force reverses there, while the exact slip u0 exp(-b (1 - cos phi t)) never does. The series "
                             "spin falls exactly while its slip is negative: its rise-then-fall comes from the "
                             "truncation, not from the law")
    return notes


def _jacobian(model: _Model, slots, values) -> np.ndarray:
    """Central-difference Jacobian of the weighted residual in scaled units of the free parameters."""
    cols = []
    for s in (s for s in slots if s.vary):
        x = values[s.pname] / s.scale
        h = 1e-4 * max(abs(x), 1e-2)
        lo, hi = dict(values), dict(values)
        lo[s.pname] = (x - h) * s.scale
        hi[s.pname] = (x + h) * s.scale
        cols.append((model.residual(hi) - model.residual(lo)) / (2 * h))
    return np.array(cols).T if cols else np.zeros((0, 0))


def _structure(law, slots, values, J) -> dict:
    """What the data can determine: free parameters at (or running into) a bound, ratio-only pairs
    that are both free, parameters with no effect, and the number of identifiable directions
    (rank of the column-normalized Jacobian)."""
    varying = [s for s in slots if s.vary]
    at_bounds = tuple(s.display for s in varying
                      if any(math.isfinite(b) and abs(values[s.pname] - b) <= 2e-3 * max(abs(b) * 1e-3, s.scale)
                             for b in (s.lower, s.upper)))
    ratios = []
    for a, b in law.ratio_only:
        for sa in (s for s in varying if s.kind == "law" and s.key == a):
            sb = [s for s in varying if s.kind == "law" and s.key == b and set(s.targets) & set(sa.targets)]
            if sb and (a, b) not in ratios:
                ratios.append((a, b))
    norms = np.linalg.norm(J, axis=0) if J.size else np.zeros(len(varying))
    top = norms.max() if norms.size else 0.0
    effect = norms > 1e-9 * max(top, 1e-300)
    no_effect = tuple(s.display for s, e in zip(varying, effect) if not e)
    k_eff = 0
    if effect.any():
        sv = np.linalg.svd(J[:, effect] / norms[effect], compute_uv=False)
        k_eff = int(np.sum(sv > 1e-6 * sv[0]))
    return {"at_bounds": at_bounds, "ratios": tuple(ratios), "no_effect": no_effect, "k_eff": k_eff,
            "n_free": len(varying)}


def _in_ratio(s, structure) -> bool:
    return s.kind == "law" and any(s.key in pair for pair in structure["ratios"])


def _jacobian_errors(slots, values, J, structure, redchi) -> dict:
    """Standard errors [SI] from the Jacobian of the identifiable directions, scaled by the reduced
    chi-square as lmfit's are: free parameters that have an effect and are not in a ratio-only pair,
    plus each such pair as its ratio. Returns {"errors": {display: err}, "derived": {label: (value, err,
    unit, slot)}, "correl": {(a, b): r}}."""
    cols, entries = [], []
    for k, s in enumerate(s for s in slots if s.vary):
        if s.display in structure["no_effect"]:
            continue
        if not _in_ratio(s, structure):
            cols.append(J[:, k])
            entries.append((s.display, s.scale, None))
            continue
        pair = next(pr for pr in structure["ratios"] if s.key in pr)
        if s.key != pair[0]:
            continue
        b = next(x for x in slots if x.kind == "law" and x.key == pair[1] and set(x.targets) & set(s.targets))
        cols.append(J[:, k] * values[b.pname] / s.scale)  # d res / d(a/b) = J_a b / scale_a
        label = f"{pair[0]}/{pair[1]}" + s.display[len(s.key):]
        unit = f"{s.unit}/{b.unit}" if b.unit else s.unit
        entries.append((label, 1.0, (values[s.pname] / values[b.pname], unit, s)))
    errors, derived = {}, {}
    cov = None
    if cols and np.isfinite(redchi):
        A = np.array(cols).T
        An = A / np.maximum(np.linalg.norm(A, axis=0), 1e-300)
        if np.linalg.matrix_rank(An, tol=1e-8) == A.shape[1]:
            cov = np.linalg.inv(A.T @ A) * redchi
    correl = {}
    for i, (name, conv, extra) in enumerate(entries):
        err = float(np.sqrt(max(cov[i, i], 0.0))) * conv if cov is not None else None
        if extra is None:
            if err is not None:
                errors[name] = err
        else:
            derived[name] = (extra[0], err, extra[1], extra[2])
        if cov is not None:
            for j in range(i + 1, len(entries)):
                denom = math.sqrt(max(cov[i, i] * cov[j, j], 1e-300))
                a, b = sorted((name, entries[j][0]))
                correl[(a, b)] = float(cov[i, j] / denom)
    return {"errors": errors, "derived": derived, "correl": correl}


def _param_results(slots, best, targets, structure, jac) -> dict[str, ParamResult]:
    """ParamResults in SI: lmfit's error bars; none where the data cannot give one (ratio-only,
    no effect); the Jacobian's over the identifiable directions where lmfit gave none or where a
    degeneracy makes its covariance unreliable. Ratio-only pairs add their ratio ('derived')."""
    out = {}
    degenerate = bool(structure["ratios"] or structure["no_effect"])  # lmfit's covariance is then unreliable
    for s in slots:
        p = best[s.pname]
        err = p.stderr * s.scale if (s.vary and p.stderr is not None and np.isfinite(p.stderr)) else None
        if s.display in structure["no_effect"] or (s.vary and _in_ratio(s, structure)):
            err = None
        elif s.vary and (err is None or degenerate):
            err = jac["errors"].get(s.display)
        out[s.display] = ParamResult(s.display, s.key, s.kind, p.value * s.scale, err, s.unit, s.vary, s.value,
                                     s.lower, s.upper, tuple(targets[i].name for i in s.targets), s.fixed_by)
    for name, (value, err, unit, slot) in jac["derived"].items():
        out[name] = ParamResult(name, name.split("[")[0], "derived", value, err, unit, False, value, 0.0, math.inf,
                                tuple(targets[i].name for i in slot.targets),
                                "derived: the combination the data determine")
    return out


def _verdict(structure, presults, correl) -> Identifiability:
    """Warnings a reader can act on, and a one-line verdict."""
    if not structure["n_free"]:
        return Identifiability("nothing fitted: every parameter is held")
    warn, missing = [], {}
    for name in structure["at_bounds"]:
        warn.append(f"{name} is at (or running into) a bound of its allowed range")
        missing[name] = "at a bound, where the error is not defined"
    for a, b in structure["ratios"]:
        warn.append(f"{a} and {b} enter only as {a}/{b}: their separate values mean nothing and get no error "
                    f"bars; fix one (a dataset's [fixed] table) to determine the other; {a}/{b} is reported")
    for name in structure["no_effect"]:
        warn.append(f"{name} has no effect on the prediction near the best fit (a term multiplied by dA/dt = 0, "
                    "or a body stuck throughout)")
    ratio_keys = {k for pair in structure["ratios"] for k in pair}
    for p in presults.values():
        if not p.vary or p.stderr is not None:
            continue
        if p.name in structure["no_effect"]:
            missing.setdefault(p.name, "has no effect on the prediction")
        elif p.kind == "law" and p.key in ratio_keys:
            missing.setdefault(p.name, "enters only through a ratio")
        else:
            missing.setdefault(p.name, "the covariance matrix is singular: parameters not separately determined")
            warn.append(f"{p.name} has no error bar: {missing[p.name]}")
    high = []
    for (a, b), r in correl.items():
        ka, kb = presults[a].key, presults[b].key
        if abs(r) > CORRELATION_LIMIT and not (ka in ratio_keys and kb in ratio_keys):
            high.append((a, b, r))
            warn.append(f"{a} and {b} are correlated (r = {r:+.3f}): the data determine a combination of them "
                        "better than either")
    problems = [label for label, flag in (("parameter at a bound", structure["at_bounds"]),
                                          ("ratio-only pair", structure["ratios"]),
                                          ("parameter without effect", structure["no_effect"]),
                                          ("strong correlation", high), ("missing error bars", missing)) if flag]
    verdict = "identifiable" if not problems else "not fully identifiable: " + ", ".join(problems)
    return Identifiability(verdict, tuple(warn), structure["at_bounds"], missing, tuple(high), structure["ratios"],
                           structure["no_effect"])
