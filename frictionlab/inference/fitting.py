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
  different units fit together.
* The likelihood follows what the dataset says about its noise (``Dataset.noise_kind``): 'known'
  sigma is used as given (-2 ln L = chi2 + sum ln(2 pi sigma_i^2), error bars NOT scaled);
  'assumed' sigma is profiled out, one scale per dataset (-2 ln L = n ln(chi2/n) + n +
  sum ln(2 pi sigma_i^2), one more parameter in AIC/AICc/BIC, error bars scaled by sqrt(reduced
  chi2)). The constant is kept, so -2 ln L of different datasets add. A derived series (omega
  smoothed from theta) has correlated points: it gets no likelihood, no criteria, no error bars.
* Every fit carries its goodness of fit (``goodness.py``) and plausibility flags (``plausibility.py``). With several datasets, law parameters are shared (a global
  fit) unless named in ``local``.
* Predictions go through ``predict``; a dataset kind plugs in with ``register_predictor``.
* ``timeout`` is a time budget per fit in seconds (None: none): a fit that exceeds it is a failed
  result saying so. It is checked before every evaluation of the model and, in the main thread,
  by an alarm that interrupts a single evaluation that runs away.
* A fit needs at least one data point more than it has free parameters; with fewer it is skipped
  with that reason, never ranked.
* ``rtol`` is the ODE tolerance of the fit's predictions (None: ``predict.FIT_RTOL``, 1e-10); it
  is an argument of each call, so fits at different tolerances may run in parallel threads.
"""
from __future__ import annotations

import math
import re
import signal
import threading
import time
import warnings
from collections.abc import Mapping, Sequence
from contextlib import contextmanager

import attrs
import numpy as np

from ..core.arguments import as_items, check_type
from ..core.errors import DatasetError, FrictionLabError, ParameterError, SolverError
from ..physics.registry import get_law
from ..physics.scene import Scene
from . import levmar
from .goodness import combine, goodness
from .identifiability import (
    Identifiability,
    find_structure,
    in_ratio,
    jacobian,
    jacobian_errors,
    make_verdict,
)
from .plausibility import check_plausibility
from .predict import (
    PREDICTORS,
    SCENE_QUANTITIES,
    SkipDataset,
    Target,
    applicable_solvers,
    auto_solver,
    get_scene_quantity,
    has_scene_quantity,
    make_target,
    predict,
    register_predictor,
    set_scene_quantity,
    takes_rtol,
)

__all__ = ["DatasetFit", "FitResult", "ParamResult", "PREDICTORS", "SCENE_QUANTITIES", "SkipDataset", "Stats", "Target",
           "applicable_solvers", "auto_solver", "fit", "get_scene_quantity", "make_target", "predict",
           "register_predictor", "set_scene_quantity"]

PENALTY = 1e4  # weighted residual per point when the model cannot be evaluated
ODE_STARTS = 2  # at most this many starts are refined when a dataset needs the (costlier) ODE solver
VALLEY_R = 0.999  # |correlation| at an ODE fit's optimum above which further starts are not run (see _valley)
FTOL = 1e-6  # relative chi-square and step tolerances of Levenberg-Marquardt


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
    likelihood: str = "assumed"  # 'known' | 'assumed' | 'mixed' | 'none' (see the module docstring)
    neg2loglik: float = math.nan  # -2 ln L at the best fit, constant included
    k_lik: int = 0  # parameters counted by AIC/AICc/BIC: n_params plus one profiled sigma per assumed dataset
    likelihood_reason: str = ""  # why this likelihood (the dataset's [noise] kind)


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
    goodness: object = None  # goodness.Goodness of this dataset's residuals

    @property
    def name(self) -> str:
        return self.target.name

    @property
    def residual(self) -> np.ndarray:
        return self.model - self.target.y

    def trajectory(self, law, t=None, n: int = 401):
        """The best-fit trajectory on times t (default: n points over the scene), or None for
        kinds without a time series."""
        from ..solve.solvers import simulate

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
    wall_time: float = 0.0  # seconds on the clock
    cpu_time: float = 0.0  # CPU seconds of the fitting thread
    message: str = ""
    notes: tuple[str, ...] = ()
    goodness: object = None  # goodness.Goodness over the fitted datasets (Bonferroni over a group)
    flags: tuple[str, ...] = ()  # plausibility.check: why the fit is physically implausible ('' if none)
    plausibility: dict = attrs.field(factory=dict)  # the numbers behind the flags (SI)
    #: lmfit's MinimizerResult of the best start, in SI (None when nothing was fitted); its parameter
    #: names are identifiers ('lam', 'scene_u0__0'); ``params`` holds the display names.
    minimizer_result: object = attrs.field(default=None, repr=False)

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @property
    def lmfit_params(self):
        """The parameters as ``lmfit.Parameters`` in SI (values, standard errors, bounds, correlations),
        named as in ``params`` with characters lmfit does not accept replaced by '_'."""
        from .frames import lmfit_parameters

        return lmfit_parameters(self)

    def fit_report(self, **kwargs) -> str:
        """lmfit's fit report of this fit (SI units, ours statistics first); kwargs go to lmfit.fit_report."""
        from .frames import fit_report

        return fit_report(self, **kwargs)

    def to_dataframe(self):
        """The parameters as a tidy pandas DataFrame, one row per parameter, with units."""
        from .frames import parameters_frame

        return parameters_frame([self])

    def __repr__(self) -> str:
        on = ", ".join(self.datasets)
        if not self.ok:
            return f"<FitResult {self.law} [{self.solver}] on {on}: {self.status}: {self.reason}>"
        from ..core.display import param_text

        ps = ", ".join(f"{p.name} = {param_text(p.value, p.stderr, p.unit)}" for p in self.params.values()
                       if p.vary or p.kind == "derived")
        return f"<FitResult {self.law} [{self.solver}] on {on}: {ps}; reduced chi2 {self.stats.redchi:.3g}>"

    def _repr_html_(self) -> str:
        from .frames import fit_html

        return fit_html(self)

    def value(self, name: str) -> float:
        return self.params[name].value

    @property
    def determined(self) -> tuple[str, ...]:
        """Names of the parameters the data determine: the fitted ones, except those without effect
        or entering only through a ratio, plus the derived combinations (e.g. 'eta/h')."""
        ident = self.identifiability
        arbitrary = set(ident.no_effect) | {k for pair in ident.ratio_only for k in pair} if ident else set()
        return tuple(k for k, p in self.params.items()
                     if (p.vary and not {k, p.key} & arbitrary) or p.kind == "derived")

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
        lines.append(f"  likelihood: {s.likelihood} sigma ({s.likelihood_reason})" if s.likelihood != "none"
                     else f"  likelihood: none ({s.likelihood_reason})")
        if self.goodness is not None:
            verdict = {True: "fits", False: "does not fit", None: "not tested"}[self.goodness.fits]
            lines.append(f"  goodness of fit: {verdict}: {self.goodness.text} ({self.goodness.reason})")
        for flag in self.flags:
            lines.append(f"  FLAG (implausible): {flag}")
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
        if len(bounds) == 3 and not lo <= float(bounds[2]) <= hi:
            raise ParameterError(f"free scene quantity '{name}': start {float(bounds[2]):g} is outside its bounds "
                                 f"[{lo:g}, {hi:g}]")
        having = [i for i, tg in enumerate(targets) if has_scene_quantity(tg.dataset.scene, name)]
        if not having:  # a quantity freed for a comparison applies to the datasets whose scene has it
            get_scene_quantity(targets[0].dataset.scene, name)  # the one-line error naming what is missing
        for i in having:
            tg = targets[i]
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


class FitTimeout(BaseException):
    """A fit ran past its time budget (a BaseException, so that no handler of a law's errors keeps it)."""


@contextmanager
def _alarm(seconds: float | None):
    """Raise FitTimeout in the main thread after ``seconds`` (no-op elsewhere, or if an alarm is set)."""
    if (seconds is None or not hasattr(signal, "setitimer") or threading.current_thread() is not threading.main_thread()
            or signal.getitimer(signal.ITIMER_REAL)[0] > 0):
        yield
        return

    def ring(signum, frame):
        raise FitTimeout()

    old = signal.signal(signal.SIGALRM, ring)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


class _Model:
    """Evaluates the weighted residual for a vector of scaled parameter values."""

    def __init__(self, law, targets, solvers, slots, rtol=None, deadline=None):
        self.law, self.targets, self.solvers, self.slots, self.rtol = law, targets, solvers, slots, rtol
        self.deadline = deadline  # time.monotonic() after which an evaluation raises FitTimeout
        self.failures = 0
        self.last_error = ""
        self.nfev = 0
        self._last = None  # (values, models, residual) of the last evaluation that solved every target
        self.progress = None  # fitprogress.FitProgress, told of every evaluation

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
        """Each target's model at SI slot values; the last evaluation's when it was at these values
        (lmfit's last call is at its best values, where the fit reads the models next)."""
        if self._last is not None and self._last[0] == values:
            return list(self._last[1])
        return [predict(self.law, tg, p, solver, scene, self.rtol)
                for tg, solver, (p, scene) in zip(self.targets, self.solvers, self.split(values))]

    def residual(self, values) -> np.ndarray:
        if self.deadline is not None and time.monotonic() > self.deadline:
            raise FitTimeout()
        if self._last is not None and self._last[0] == values:  # scipy's leastsq calls at the start point twice
            return self._last[2].copy()
        self.nfev += 1
        self._last = None
        if self.progress is not None:
            self.progress.tick()
        out, ms = [], []
        for tg, solver, (p, scene) in zip(self.targets, self.solvers, self.split(values)):
            try:
                m = predict(self.law, tg, p, solver, scene, self.rtol)
                if m.shape != tg.y.shape or not np.isfinite(m).all():
                    raise SolverError(f"prediction for '{tg.name}' is not finite or has the wrong shape")
                out.append((m - tg.y) / tg.sigma)
                ms.append(m)
            except SkipDataset:
                raise
            except FrictionLabError as exc:
                self.failures += 1
                self.last_error = str(exc)
                out.append(np.full(tg.y.shape, PENALTY))
        r = np.concatenate(out)
        if len(ms) == len(self.targets):
            self._last = (dict(values), ms, r.copy())
        return r


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


def _valley(result) -> str:
    """Why a converged Levenberg-Marquardt run ended in a valley the data do not close ('' if not):
    two parameters correlated beyond VALLEY_R, or a parameter at a bound. Another start ends in the
    same valley (the comparison's area-rate fit on a dry incline walks mu -> 0, eta' -> infinity
    with mu eta' fixed, from either start), so an ODE fit does not pay for it twice."""
    for p in result.params.values():
        if not p.vary:
            continue
        if any(abs(v - p.value) <= 1e-9 * max(abs(p.value), 1.0) for v in (p.min, p.max) if math.isfinite(v)):
            return f"{p.name} at a bound"
        for other, r in (p.correl or {}).items():
            if abs(r) >= VALLEY_R:
                return f"{p.name} and {other} correlated at r = {r:.4f}"
    return ""


def _search(lmfit, model: _Model, params, slots, solvers, scan: int, n_starts: int, max_nfev, scale_covar: bool = True,
            direct: bool = False):
    """Score a grid of starts, refine the best distinct ones with Levenberg-Marquardt, keep the lowest
    chi-square. Returns (parameters, success, message, lmfit MinimizerResult or None, notes). scale_covar:
    scale lmfit's error bars by sqrt(reduced chi2) (only when sigma is not known). direct: run lmfit's
    Levenberg-Marquardt through ``levmar.leastsq`` (the same numbers without lmfit's bookkeeping; its
    result is not a MinimizerResult), lmfit itself where that declines."""
    varying = [s for s in slots if s.vary]
    if not varying:
        return params, True, "nothing to fit: every parameter is held", None, []
    slow = any(x.startswith("ode") for x in solvers)
    starts = [{s.pname: params[s.pname].value for s in varying}]
    budget = max_nfev or 200 * (len(varying) + 1)
    if model.progress is not None:
        from .fitprogress import LM_EVALS

        lm = LM_EVALS * (len(varying) + 1)
        model.progress.stage("scanning start points", scan, total=scan + n_starts * lm + 2 * len(varying) + 2)
    if scan:
        fixed_part = {s.pname: s.value / s.scale for s in slots if not s.vary}
        scored = []
        for cand in _start_grid(varying, np.random.default_rng(0), scan):
            vals = {**fixed_part, **cand}
            r = model.residual({s.pname: vals[s.pname] * s.scale for s in slots})
            scored.append((float(r @ r), len(scored), cand))
        scored.sort(key=lambda x: x[:2])  # ties keep grid order: the given start wins
        starts = _distinct(scored, min(n_starts, ODE_STARTS) if slow else n_starts)
    best, notes = None, []
    for i, start in enumerate(starts):
        for k, v in start.items():  # every varying parameter; lmfit works on its own copy
            params[k].set(value=v)
        if model.progress is not None:
            model.progress.stage(f"Levenberg-Marquardt start {i + 1} of {len(starts)}", lm,
                                 total=model.progress.done + (len(starts) - i) * lm + 2 * len(varying) + 2)
        r = None
        if direct:
            before = model.nfev, model.failures, model.last_error, model._last
            r = levmar.leastsq(lambda v: model.residual({s.pname: v[s.pname] * s.scale for s in slots}), params,
                               scale_covar, budget, epsfcn=1e-10, ftol=FTOL, xtol=FTOL)
            if r is None:  # lmfit takes another path here: run it, from the same state of the model
                model.nfev, model.failures, model.last_error, model._last = before
        if r is None:
            mini = lmfit.Minimizer(lambda ps: model.residual(_si(ps, slots)), levmar.lmfit_parameters(params),
                                   scale_covar=scale_covar, max_nfev=budget)
            r = mini.minimize(method="leastsq", epsfcn=1e-10, ftol=FTOL, xtol=FTOL)
        if best is None or (r.success, -r.chisqr) > (best.success, -best.chisqr):
            best = r
        why = _valley(r) if slow and r.success and i + 1 < len(starts) else ""
        if why:
            notes.append(f"one Levenberg-Marquardt start of {len(starts)}: the first ended where the data do not "
                         f"determine the parameters ({why}), where another start ends too")
            break
    return best.params, bool(best.success), str(best.message), best, notes


def fit(law, datasets, solver: str = "auto", *, free: Mapping[str, Sequence[float]] | None = None,
        fixed: Mapping[str, float] | None = None, local: Sequence[str] = (),
        initial: Mapping[str, float] | None = None, observable: str | None = None, derive: str | None = None,
        scan: int = 125, n_starts: int = 3, max_nfev: int | None = None, rtol: float | None = None,
        timeout: float | None = None, checks: bool = True, errors: bool = True, progress=None) -> FitResult:
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
    rtol: relative (and scaled absolute) tolerance of every ODE solve in the fit, in (0, 1);
    None uses predict.FIT_RTOL (1e-6; simulate's default is 1e-10). Closed forms and the series ignore it.
    timeout: time budget of the fit in seconds (None: none); past it the fit is 'failed'.
    checks: False skips the plausibility flags and the SI copy of lmfit's result (``minimizer_result``
    None): for replicate refits (equivalence, bootstrap, transfer) that read only the values, their
    error bars, the chi-square and the information criteria, which are the same either way.
    errors: False skips the error analysis beyond lmfit's (the Jacobian, and what it shows: parameters
    without effect, ratio-only pairs, identifiable directions; every free parameter counts in k): for
    refits that read only the values and the chi-square (the equivalence test's replicates).
    progress(done, total, label): told the stage (start scan, each Levenberg-Marquardt start, error
    analysis) and its count of model evaluations (core.progress.Progress takes it).
    """
    import lmfit  # slow to import: only when fitting

    check_type(solver, str, "fit: solver", "a solver name such as 'auto', 'exact' or 'ode'")
    law = get_law(law)
    started, cpu_started = time.perf_counter(), time.thread_time()
    items = as_items(datasets, "fit: datasets")
    if not items:
        raise DatasetError("fit: no datasets given")
    names = tuple(d.name if hasattr(d, "name") else str(d) for d in items)  # str() of a Target prints its arrays

    def give_up(status, reason, **kw):
        return FitResult(law=law.name, solver=solver, datasets=names, status=status, reason=reason,
                         wall_time=time.perf_counter() - started, cpu_time=time.thread_time() - cpu_started, **kw)

    try:
        targets = [d if isinstance(d, Target) else make_target(d, observable, derive) for d in items]
    except SkipDataset as exc:
        return give_up("skipped", str(exc))
    names = tuple(t.name for t in targets)
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:  # its points would count twice and the error bars shrink by sqrt(2)
        raise DatasetError(f"fit: dataset '{twice[0]}' is given more than once; give each dataset once")
    for name in list(fixed or {}) + list(local) + list(initial or {}):
        law.spec(name)  # unknown names are input errors
    law.resolve({**(initial or {}), **(fixed or {})})  # so are held or start values outside the bounds
    if rtol is not None and (isinstance(rtol, bool) or not isinstance(rtol, (int, float)) or not 0 < rtol < 1):
        raise ParameterError(f"fit: rtol must be a number in (0, 1), got {rtol!r}")
    if timeout is not None and (isinstance(timeout, bool) or not isinstance(timeout, (int, float))
                                or not 0 < timeout < math.inf):
        raise ParameterError(f"fit: timeout must be a positive number of seconds, got {timeout!r}")
    solvers = []
    for tg in targets:
        if tg.dataset.kind not in PREDICTORS:
            return give_up("skipped", f"no predictor for dataset kind '{tg.dataset.kind}' (dataset '{tg.name}')")
        if tg.dataset.scene is None:
            return give_up("skipped", f"dataset '{tg.name}' has no scene")
        if rtol is not None and not takes_rtol(PREDICTORS[tg.dataset.kind]):
            raise ParameterError(f"fit: rtol given, but the predictor of dataset kind '{tg.dataset.kind}' "
                                 "takes no 'rtol' keyword")
        ok = applicable_solvers(law, tg.dataset.scene)
        s = auto_solver(law, tg.dataset.scene) if solver == "auto" else solver
        base = s.partition(":")[0]
        if base not in ok:
            from ..solve.solvers import parse_solver

            parse_solver(s)  # raises the one-line error for an unknown solver
        if ok.get(base):
            return give_up("skipped", f"{base} on '{tg.name}': {ok[base]}")
        solvers.append(s)
    slots = _law_slots(law, targets, dict(fixed or {}), set(local), dict(initial or {}))
    slots += _scene_slots(targets, dict(free or {}))
    model = _Model(law, targets, solvers, slots, rtol, None if timeout is None else time.monotonic() + timeout)
    if progress is not None:
        from .fitprogress import FitProgress

        model.progress = FitProgress(progress, f"{law.name} on {', '.join(names)}", scan + n_starts)
    bounds = [(_lmfit_bound(s.lower, s) / s.scale, _lmfit_bound(s.upper, s) / s.scale) for s in slots]
    if not checks and all(lo < hi and (math.isinf(lo) or math.isinf(hi) or hi - lo > 1e-13 + 1e-13 * abs(hi))
                          for lo, hi in bounds):  # an interval lmfit accepts
        params = {s.pname: levmar.Param(s.pname, s.value / s.scale, lo, hi, s.vary) for s, (lo, hi) in zip(slots, bounds)}
    else:  # lmfit's own (and its error where the bounds are no interval)
        params = lmfit.Parameters()
        for s, (lo, hi) in zip(slots, bounds):
            params.add(s.pname, value=s.value / s.scale, vary=s.vary, min=lo, max=hi)
    varying = [s for s in slots if s.vary]
    solver_label = solver if solver != "auto" else "+".join(dict.fromkeys(solvers))
    n_points = sum(t.y.size for t in targets)
    if n_points < len(varying) + 1:
        return give_up("skipped", f"{', '.join(names)}: {n_points} data point{'s' * (n_points != 1)} for {len(varying)} free parameter"
                                  f"{'s' * (len(varying) != 1)}: a fit needs at least {len(varying) + 1}")

    likelihood = _likelihood(targets)
    success, message = True, ""
    try:
        with _alarm(timeout):
            best_params, success, message, best, search_notes = _search(lmfit, model, params, slots, solvers, scan,
                                                                        n_starts, max_nfev,
                                                                        scale_covar=likelihood != "known",
                                                                        direct=not checks)
            values = _si(best_params, slots)
            models = model.models(values)
        model.deadline = None  # the error analysis below is bounded work
    except FitTimeout:
        return give_up("failed", f"exceeded its time budget of {timeout:g} s (--fit-timeout)", nfev=model.nfev)
    except SkipDataset as exc:
        return give_up("skipped", str(exc))
    except FrictionLabError as exc:  # an aborted search leaves parameters that mean nothing: say it did not converge
        why = f"did not converge: {message}" if not success else f"the model cannot be evaluated at the best parameters: {exc}"
        return give_up("failed", why, nfev=model.nfev)
    except Exception as exc:  # an optimizer or law crash is a failed fit, not a crashed comparison
        return give_up("failed", f"{type(exc).__name__}: {exc}", nfev=model.nfev)

    if model.progress is not None:
        model.progress.stage("error analysis", 2 * len(varying) + 2)
    if errors:
        J = jacobian(model, slots, values)
        structure = find_structure(law, slots, values, J)
    else:
        n_free = len(varying)
        structure = {"at_bounds": (), "ratios": (), "no_effect": (), "k_eff": n_free, "n_free": n_free}
    k_each = structure["k_eff"] / len(targets)  # a group's parameters shared out for each member's test
    per = []
    for tg, solver_i, (p, scene), m in zip(targets, solvers, model.split(values), models):
        r = m - tg.y
        per.append(DatasetFit(tg, solver_i, p, scene, m, float(r @ r), float(np.sqrt(np.mean(r**2))),
                              float(np.sum((r / tg.sigma) ** 2)),
                              goodness(r / tg.sigma, round(k_each), _likelihood([tg]))))
    chisqr = sum(d.chisqr for d in per)
    stats = _stats(n_points, structure["k_eff"], len(varying), chisqr, per)
    status, reason = "ok", ""
    if not all(np.all(np.isfinite(d.model)) for d in per):
        status, reason = "failed", "the best-fit model is not finite"
    elif not success:
        status, reason = "failed", f"did not converge: {message}"
    elif model.failures and chisqr >= PENALTY**2:
        status, reason = "failed", f"the solver failed at every trial: {model.last_error}"
    notes = list(search_notes)
    if model.failures:
        notes.append(f"{model.failures} of {model.nfev} evaluations could not be solved and were penalized "
                     f"(last: {model.last_error})")
    notes += _series_notes(law, per)
    jac = (jacobian_errors(slots, values, J, structure, stats.redchi if likelihood != "known" else 1.0) if errors
           else {"errors": {}, "derived": {}, "correl": {}})
    presults = _param_results(slots, best_params, targets, structure, jac)
    if likelihood == "none":  # error bars rest on independent points: a smoothed series has none to give
        presults = {k: attrs.evolve(p, stderr=None) for k, p in presults.items()}
        notes.append("fitted to a derived series (omega smoothed from theta): its points are correlated, so no "
                     "chi-square, information criterion or error bar is valid; fit theta itself for those")
    correl = {}
    if structure["ratios"] or structure["no_effect"]:  # lmfit's covariance is degenerate: use the identifiable part
        correl = jac.get("correl", {})
    else:
        for s in varying:
            for other, r in (best_params[s.pname].correl or {}).items():
                o = next(x for x in slots if x.pname == other)
                if s.display < o.display:
                    correl[(s.display, o.display)] = float(r)
    ident = make_verdict(structure, presults, correl)
    flags, numbers, nfev = (), {}, model.nfev
    if status == "ok" and checks:
        if model.progress is not None:
            model.progress.stage("plausibility checks", 1)
        flags, numbers = check_plausibility(law, per, model, slots, values, likelihood)
    if model.progress is not None:
        model.progress.finish(f"{status} after {model.nfev} evaluations")
    return FitResult(law=law.name, solver=solver_label, datasets=names, status=status, reason=reason,
                     params=presults, correlations=correl, stats=stats, identifiability=ident,
                     per_dataset=tuple(per), nfev=nfev, wall_time=time.perf_counter() - started,
                     cpu_time=time.thread_time() - cpu_started,
                     message=message, notes=tuple(notes), goodness=combine([d.goodness for d in per]),
                     flags=tuple(flags), plausibility=numbers, minimizer_result=_si_result(best, slots) if checks else None)


def _likelihood(targets) -> str:
    """'none' if a target is a derived (smoothed) series, else the datasets' noise kind ('mixed' if they differ)."""
    if any(t.derivation for t in targets):
        return "none"
    kinds = {t.dataset.noise_kind for t in targets}
    return kinds.pop() if len(kinds) == 1 else "mixed"


LIKELIHOOD_REASON = {
    "known": "[noise] kind = known: sigma is measured, so the Gaussian likelihood uses it as given "
             "(AIC = chi2 + 2k + sum ln(2 pi sigma^2)); error bars are not rescaled",
    "assumed": "[noise] kind = assumed (or not given): sigma is a guess, so it is profiled out "
               "(-2 ln L = n ln(chi2/n) + n + sum ln(2 pi sigma^2), one more parameter); error bars are scaled "
               "by sqrt(reduced chi2)",
    "mixed": "the datasets differ: known sigma used where measured, profiled where assumed",
    "none": "fitted to a derived series (omega smoothed from theta): correlated points, no valid likelihood",
}


def neg2loglik(chisqr: float, n: int, sigma: np.ndarray, kind: str) -> float:
    """-2 ln L of one dataset [constant included]: chi2 + C if sigma is known, n ln(chi2/n) + n + C if
    it is profiled (the maximum over a common scale of the declared sigmas); C = sum ln(2 pi sigma_i^2)."""
    const = float(np.sum(np.log(2 * math.pi * np.asarray(sigma, dtype=float) ** 2)))
    if kind == "known":
        return chisqr + const
    return n * math.log(max(chisqr, np.finfo(float).tiny) / n) + n + const


def _si_result(best, slots):
    """A copy of lmfit's MinimizerResult in SI: the optimizer works on parameters divided by their
    typical size; values, bounds, errors, start values and the covariance are multiplied back."""
    if best is None:
        return None
    import copy

    scale = {s.pname: s.scale for s in slots}
    r = copy.copy(best)
    r.params = best.params.copy()
    for name, p in r.params.items():
        f = scale[name]
        p.set(min=p.min * f, max=p.max * f)  # bounds first: a value is clipped into them
        p.set(value=p.value * f)
        p.init_value = None if p.init_value is None else p.init_value * f
        p.stderr = None if p.stderr is None else p.stderr * f
    if getattr(best, "covar", None) is not None:
        d = np.array([scale[n] for n in best.var_names])
        r.covar = best.covar * np.outer(d, d)
    r.init_vals = [v * scale[n] for v, n in zip(best.init_vals, best.var_names)]
    r.init_values = {n: v * scale[n] for n, v in best.init_values.items()}
    return r


def _stats(n, k, k_free, chisqr, per) -> Stats:
    """Information criteria from the likelihood the datasets' noise calls for (module docstring):
    AIC = -2 ln L + 2 k', AICc = AIC + 2k'(k'+1)/(n-k'-1), BIC = -2 ln L + k' ln n, where k' = k plus
    one profiled sigma per assumed-noise dataset. NaN for a derived (smoothed) series."""
    single = len(per) == 1
    kind = _likelihood([d.target for d in per])
    base = dict(n_points=n, n_params=k, n_free=k_free, chisqr=chisqr, redchi=chisqr / (n - k) if n > k else math.inf,
                rss=per[0].rss if single else math.nan, rmse=per[0].rmse if single else math.nan,
                likelihood=kind, likelihood_reason=LIKELIHOOD_REASON[kind])
    if kind == "none":
        return Stats(aic=math.nan, aicc=math.nan, bic=math.nan, **base)
    ll, kk = 0.0, k
    for d in per:
        own = d.target.dataset.noise_kind
        ll += neg2loglik(d.chisqr, d.target.y.size, d.target.sigma, own)
        kk += own != "known"
    aic = ll + 2 * kk
    aicc = aic + (2 * kk * (kk + 1) / (n - kk - 1) if n - kk - 1 > 0 else math.inf)
    return Stats(aic=aic, aicc=aicc, bic=ll + kk * math.log(n), neg2loglik=ll, k_lik=kk, **base)


def _series_notes(law, per) -> list[str]:
    from ..solve.solvers.series import B_ACCURATE

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


def _param_results(slots, best, targets, structure, jac) -> dict[str, ParamResult]:
    """ParamResults in SI: lmfit's error bars; none where the data cannot give one (ratio-only,
    no effect); the Jacobian's over the identifiable directions where lmfit gave none or where a
    degeneracy makes its covariance unreliable. Ratio-only pairs add their ratio ('derived')."""
    out = {}
    degenerate = bool(structure["ratios"] or structure["no_effect"])  # lmfit's covariance is then unreliable
    for s in slots:
        p = best[s.pname]
        err = p.stderr * s.scale if (s.vary and p.stderr is not None and np.isfinite(p.stderr)) else None
        if s.display in structure["no_effect"] or (s.vary and in_ratio(s, structure)):
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


