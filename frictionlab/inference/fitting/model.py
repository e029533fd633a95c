"""The fit's machinery: parameter slots (law parameters and freed scene quantities, scaled for the
optimizer), the weighted-residual model, the time budget, and the multi-start Levenberg-Marquardt search."""
from __future__ import annotations

import math
import re
import time
from collections.abc import Mapping

import attrs
import numpy as np

from ...core.errors import FrictionLabError, ParameterError, SolverError
from ...physics.freeable import SCENE_SHOWN
from . import lsrefit
from .alarm import FitTimeout
from .starts import distinct, sampled_starts, start_grid
from .predict import (
    SCENE_QUANTITIES,
    SkipDataset,
    design,
    get_scene_quantity,
    has_scene_quantity,
    predict,
    predict_many,
    set_scene_quantity,
)

PENALTY = 1e4  # weighted residual per point when the model cannot be evaluated
ODE_STARTS = 2  # at most this many starts are refined when a dataset needs the (costlier) ODE solver
VALLEY_R = 0.999  # |correlation| at an ODE fit's optimum above which further starts are not run (see _valley)
FTOL = 1e-6  # relative chi-square and step tolerances of Levenberg-Marquardt
SHARED_MAX = (512, 2**22)  # predictions and their floats kept by ``_shared_predict`` (all dropped when either is reached)

#: Predictions by (law, what the predictor reads of the dataset (``predict.design``), solver, scene, rtol,
#: parameters), the objects compared by identity and kept alive with the entry. Refits warm-started at one fit's
#: values (an equivalence test's and a bootstrap's replicates) begin with the same evaluations, since a model
#: never reads the data it is fitted to: the start and its finite-difference steps. A deterministic prediction is
#: computed once for all of them.
_SHARED: dict = {}
_SHARED_FLOATS = [0]  # floats held in _SHARED's predictions


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
    shown: str = ""  # the unit the value is shown in ("": unit)


def _ident(text: str) -> str:
    s = re.sub(r"\W", "_", text)
    return s if re.match(r"[A-Za-z_]", s) else f"p_{s}"


def held_value(law, name: str, dataset) -> float:
    """The dataset's ``[fixed]`` value of the law's parameter ``name`` [SI], checked against the law's bounds
    where it is used (the dataset's values may have been changed since they were read and checked)."""
    spec, value = law.spec(name), dataset.fixed[name]
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = math.nan
    if not (math.isfinite(v) and spec.lower <= v <= spec.upper):
        raise ParameterError(f"dataset '{dataset.name}': [fixed] {name} = {value!r} {spec.unit} is outside the bounds "
                             f"of law '{law.name}' [{spec.lower:g}, {spec.upper:g}] (changed after the dataset was read?)")
    return v


def _law_slots(law, targets, fixed, local, initial) -> list[_Slot]:
    slots = []
    multi = len(targets) > 1
    for spec in law.params:
        n = spec.name
        start = float(initial.get(n, spec.default))
        common = dict(kind="law", key=n, lower=spec.lower, upper=spec.upper, scale=spec.scale, unit=spec.unit,
                      shown=spec.display)
        if n in fixed:
            slots.append(_Slot(_ident(n), n, targets=tuple(range(len(targets))), value=float(fixed[n]), vary=False,
                               fixed_by="held by the caller", **common))
            continue
        held = {i: held_value(law, n, t.dataset) for i, t in enumerate(targets) if n in t.dataset.fixed}
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
                               SCENE_QUANTITIES[name], True, shown=SCENE_SHOWN.get(name, "")))
    return slots


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
        self._compiled_memory = None  # compiled_memory(self), worked out once

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
            return [m.copy() for m in self._last[1]]  # the fit result's own: shared predictions are read-only
        return [predict(self.law, tg, p, solver, scene, self.rtol)
                for tg, solver, (p, scene) in zip(self.targets, self.solvers, self.split(values))]

    def residual(self, values, given=None) -> np.ndarray:
        """The weighted residual at SI slot values; ``given``: the one target's prediction there, made already."""
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
                m = _shared_predict(self.law, tg, p, solver, scene, self.rtol) if given is None else given
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

    def residuals(self, points: list) -> list[np.ndarray]:
        """``residual`` at each of ``points`` (SI slot values), in order; one target's predictions made in one
        vectorized call where its kind offers one (``predict_many``; a start scan of impact outcomes)."""
        many = None
        if len(self.targets) == 1 and not any(s.kind == "scene" for s in self.slots) and len(points) > 1:
            tg = self.targets[0]
            many = predict_many(self.law, tg, [self.split(v)[0][0] for v in points], self.solvers[0])
        return [self.residual(v, None if many is None else many[i]) for i, v in enumerate(points)]


def _shared_predict(law, tg, p: dict, solver: str, scene, rtol) -> np.ndarray:
    """``predict``, read-only, from ``_SHARED`` when the same law, dataset, observable, solver, scene, rtol and
    parameter values were predicted before in this process (bitwise the same array)."""
    reads = design(tg)
    if reads is None:
        return predict(law, tg, p, solver, scene, rtol)
    objs = (law, scene) + reads
    key = tuple(map(id, objs)) + (solver, rtol, tuple(p.items()))
    hit = _SHARED.get(key)
    if hit is not None and all(a is b for a, b in zip(hit[0], objs)):
        return hit[1]
    m = predict(law, tg, p, solver, scene, rtol)
    m.flags.writeable = False
    if len(_SHARED) >= SHARED_MAX[0] or _SHARED_FLOATS[0] >= SHARED_MAX[1]:
        _SHARED.clear()
        _SHARED_FLOATS[0] = 0
    _SHARED[key] = (objs, m)
    _SHARED_FLOATS[0] += m.size
    return m


def _si(params, slots) -> dict[str, float]:
    return {s.pname: params[s.pname].value * s.scale for s in slots}


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


def lmfit_leastsq(lmfit, model: _Model, slots, params, scale_covar: bool, budget: int):
    """lmfit's Levenberg-Marquardt on ``model`` from lmfit ``params`` (values / scale), at most ``budget``
    evaluations: its MinimizerResult."""
    mini = lmfit.Minimizer(lambda ps: model.residual(_si(ps, slots)), params, scale_covar=scale_covar,
                           max_nfev=budget)
    return mini.minimize(method="leastsq", epsfcn=epsfcn(model), ftol=FTOL, xtol=FTOL)


#: How many times the given number of start points a compiled law with memory scores on a finer and wider grid
#: (``compiled_memory``; as many again on the widest), and the decades either side of each positive parameter's
#: start that those grids span.
MEMORY_SCAN = 4
MEMORY_DECADES = (1.5, 3.0)
#: How many times the given number of start points a compiled law with memory also draws from a Latin hypercube
#: over the finer grid's spans (``sampled_starts``: coordinates between the grid's levels), and how many of
#: the best of those it refines.
MEMORY_SAMPLED, MEMORY_SAMPLED_STARTS = 1, 2


def compiled_memory(model: _Model) -> bool:
    """True when the model is a built-in law with memory that every target solves by the ODE solver's default
    method on the compiled path (``solve.memoryrhs``): cheap enough for a wider search (MEMORY_SCAN times the
    start points and MEMORY_SAMPLED times them sampled, every start refined, no early stop in a valley, the best
    end refined again at a tighter tolerance: ``_tighter``) and solved to a tolerance that makes
    Levenberg-Marquardt's difference quotients need steps of its size (``epsfcn``)."""
    cached = getattr(model, "_compiled_memory", None)
    if cached is None:
        from ...solve.memoryrhs import available, served
        from ...solve.plan import make_plan

        try:
            cached = (bool(model.law.states) and all(s in ("ode", "ode:LSODA") for s in model.solvers)
                      and all(tg.dataset.kind in ("impact", "incline", "spring-slider") for tg in model.targets)
                      and all(served(make_plan(tg.dataset.scene, model.law)) for tg in model.targets)
                      and available())
        except FrictionLabError:
            cached = False
        model._compiled_memory = cached
    return cached


def epsfcn(model: _Model) -> float:
    """Levenberg-Marquardt's relative squared step of its forward differences: 1e-10 (steps of 1e-5 of a scaled
    parameter), or, for a compiled law with memory (``compiled_memory``), the fit's ODE tolerance: an adaptive
    solve to rtol 1e-6 moves with the parameters by about that much, so steps of 1e-5 would measure the solver's
    steps more than the law (LuGre's fit to incline-oil-a100 stalled at chi-square 2626 for it; 92 with these)."""
    if not compiled_memory(model):
        return 1e-10
    from .predict import FIT_RTOL

    return max(1e-10, FIT_RTOL if model.rtol is None else float(model.rtol))


def _search(lmfit, model: _Model, params, slots, solvers, scan: int, n_starts: int, max_nfev, scale_covar: bool = True,
            direct: bool = False, values_only: bool = False):
    """Score a grid of starts, refine the best distinct ones with Levenberg-Marquardt, keep the lowest
    chi-square. Returns (parameters, success, message, lmfit MinimizerResult or None, notes). scale_covar:
    scale lmfit's error bars by sqrt(reduced chi2) (only when sigma is not known). direct: refit through
    ``lsrefit.leastsq`` (scipy's bounded least squares from the warm start, without lmfit's bookkeeping; its
    result is not a MinimizerResult), lmfit itself where that declines. Closed forms run every start in one batch
    (``batchfit.best_start``) and Levenberg-Marquardt from the lowest end only; with values_only (direct, and the
    caller reads values and chi-square only: a replicate refit) that end is the answer."""
    varying = [s for s in slots if s.vary]
    if not varying:
        return params, True, "nothing to fit: every parameter is held", None, []
    slow = any(x.startswith("ode") for x in solvers)
    wide = slow and compiled_memory(model)
    if wide:  # cheap solves of a law with memory: a wider scan, every start refined (see compiled_memory)
        slow = False
    starts = [{s.pname: params[s.pname].value for s in varying}]
    if model.progress is not None:
        from .progress import LM_EVALS

        lm = LM_EVALS * (len(varying) + 1)
        k = scan * (MEMORY_SCAN + 1 + MEMORY_SAMPLED if wide else 1)
        model.progress.stage("scanning start points", k, total=k + n_starts * lm + 2 * len(varying) + 2)
    if scan:
        fixed_part = {s.pname: s.value / s.scale for s in slots if not s.vary}
        grid = start_grid(varying, np.random.default_rng(0), scan)
        given = fine = widest = len(grid)
        if wide and MEMORY_SCAN > 1:  # the same grid, MEMORY_SCAN - 1 times as many on a finer and wider one, and
            # as many as given on the widest (a start 3 decades off: LuGre's soft bristles on incline-oil-a400)
            grid += start_grid(varying, np.random.default_rng(1), (MEMORY_SCAN - 1) * scan, MEMORY_DECADES[0])[1:]
            fine = len(grid)
            grid += start_grid(varying, np.random.default_rng(2), scan, MEMORY_DECADES[1])[1:]
            widest = len(grid)  # and as many again sampled over the finer grid's spans, every axis continuous
            grid += sampled_starts(varying, np.random.default_rng(3), MEMORY_SAMPLED * scan, MEMORY_DECADES[0])[1:]
        points = [{s.pname: vals[s.pname] * s.scale for s in slots} for vals in ({**fixed_part, **c} for c in grid)]
        scored = [(float(r @ r), i, c) for i, (r, c) in enumerate(zip(model.residuals(points), grid))]
        scored.sort(key=lambda x: x[:2])  # ties keep grid order: the given start wins
        starts = distinct([x for x in scored if x[1] < fine], min(n_starts, ODE_STARTS) if slow else n_starts)
        if wide:  # the best of the given grid alone, as a fit of a law without memory starts, and of the widest
            starts += [c for c in distinct([x for x in scored if x[1] < given], n_starts) if c not in starts]
            starts += [c for c in distinct([x for x in scored if fine <= x[1] < widest], n_starts) if c not in starts]
            starts += [c for c in distinct([x for x in scored if x[1] >= widest], MEMORY_SAMPLED_STARTS)
                       if c not in starts]
    if not slow and (values_only or len(starts) > 1):  # closed forms: every start's run in one batch
        from .batch import best_start

        moved = best_start(model, starts)
        if moved is not None and values_only and direct:
            for k, v in moved[0].items():
                params[k].set(value=v)
            return params, True, "Fit succeeded.", lsrefit.Result(params, True, "Fit succeeded.", moved[1]), []
        if moved is not None:  # lmfit's own run from the lowest end, for its error analysis
            starts = [moved[0]]
    best, notes = None, []
    for i, start in enumerate(starts):
        for k, v in start.items():  # every varying parameter; lmfit works on its own copy
            params[k].set(value=v)
        budget = max_nfev or 200 * (len(varying) + 1)
        if model.progress is not None:
            model.progress.start(i, len(starts), lm, 2 * len(varying) + 2)
        r = None
        if direct:
            before = model.nfev, model.failures, model.last_error, model._last
            r = lsrefit.leastsq(lambda v: model.residual({s.pname: v[s.pname] * s.scale for s in slots}), params,
                               scale_covar, budget, epsfcn=epsfcn(model), ftol=FTOL, xtol=FTOL)
            if r is None:  # lmfit takes another path here: run it, from the same state of the model
                model.nfev, model.failures, model.last_error, model._last = before
        if r is None:
            r = lmfit_leastsq(lmfit, model, slots, lsrefit.lmfit_parameters(params), scale_covar, budget)
        if best is None or (r.success, -r.chisqr) > (best.success, -best.chisqr):
            best = r
        why = _valley(r) if slow and r.success and i + 1 < len(starts) else ""
        if why:
            notes.append(f"one Levenberg-Marquardt start of {len(starts)}: the first ended where the data do not "
                         f"determine the parameters ({why}), where another start ends too")
            break
    if wide and scan and not direct:  # a main fit's search (replicate refits start at its values)
        if model.progress is not None:
            model.progress.stage("refining the best end at a tighter tolerance", lm)
        best = _tighter(lmfit, model, slots, best, scale_covar, max_nfev or 200 * (len(varying) + 1))
    return best.params, bool(best.success), str(best.message), best, notes


#: The ODE tolerance, relative to the fit's, at which a compiled law with memory refines its search's best end
#: (``_tighter``).
TIGHTER = 1e-2


def _tighter(lmfit, model: _Model, slots, best, scale_covar: bool, budget: int):
    """The search's best end (an lmfit result) refined, or itself where that is no better. An adaptive solve to the
    fit's rtol changes in jumps with the parameters: rate-state-slip on incline-oil-a200 jumps by +-3 in chi-square
    between points 0.1% apart in Dc at rtol 1e-6, where the trend is 0.03 a step, so Levenberg-Marquardt's
    difference quotients see no slope and its run ends where it stands; and lmfit's bound transformation makes a
    parameter near a bound of 0 (mu0 and b there) move the least where it must move to the bound. From there,
    scipy's bounded trust region (``least_squares``: the bounds as they are, difference steps of sqrt(epsfcn)
    of each scaled parameter) runs with the ODEs solved to TIGHTER times the fit's rtol, where the jumps are that
    much smaller; then lmfit's Levenberg-Marquardt at the fit's own rtol from where it ended, for the fit's result and
    its error analysis (that run only lowers chi-square)."""
    from scipy.optimize import least_squares

    from .predict import FIT_RTOL

    varying = [s for s in slots if s.vary]
    fixed = {s.pname: s.value for s in slots if not s.vary}
    x0 = np.array([best.params[s.pname].value for s in varying])
    lo = np.array([s.lower / s.scale for s in varying])
    hi = np.array([s.upper / s.scale for s in varying])

    def residual(x):
        return model.residual({**fixed, **{s.pname: v * s.scale for s, v in zip(varying, x)}})

    rtol, step = model.rtol, math.sqrt(epsfcn(model))
    model.rtol, model._last = TIGHTER * (FIT_RTOL if rtol is None else rtol), None
    try:
        with np.errstate(all="ignore"):
            x = least_squares(residual, np.clip(x0, lo, hi), bounds=(lo, hi), x_scale="jac", diff_step=step,
                              ftol=FTOL, xtol=FTOL, max_nfev=budget).x
    except ValueError:  # scipy refuses the problem (bounds that leave a parameter no room): the search's end stands
        return best
    finally:
        model.rtol, model._last = rtol, None
    params = lsrefit.lmfit_parameters(best.params).copy()
    for s, v in zip(varying, x):
        params[s.pname].set(value=v)
    r = lmfit_leastsq(lmfit, model, slots, params, scale_covar, budget)
    return r if (r.success, -r.chisqr) > (best.success, -best.chisqr) else best
