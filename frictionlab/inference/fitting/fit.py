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
  (measured) and 'estimated' (from the data alone, io/noise.py, one value for every law) sigma are
  used as given: -2 ln L = chi2 + sum ln(2 pi sigma_i^2), error bars NOT scaled; the estimate's
  degrees of freedom go into the goodness of fit (an F test). The constant is kept, so -2 ln L of
  different datasets add. A derived series (omega smoothed from theta) or a noise-free
  reconstruction ('none') has no likelihood: no criteria, no error bars.
* Every fit carries its goodness of fit (``goodness.py``) and plausibility flags (``plausibility.py``).
  With several datasets, law parameters are shared (a global fit) unless named in ``local``.
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
import numbers
import time
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING

import attrs
import numpy as np

from ...core.arguments import as_items, check_type
from ...core.blas import one_blas_thread
from ...core.errors import DatasetError, FrictionLabError, ParameterError
from ...core.units import as_range, as_si
from ...core.workers import beat
from ...physics.registry import get_law
from . import lsrefit
from .alarm import FitTimeout, alarm
from .model import (FTOL, ODE_STARTS, PENALTY, _law_slots, _Model, _scene_slots,
                       _search, _si, lmfit_leastsq)
from .result import DatasetFit, FitResult, ParamResult, Stats
from .stats import (
    AS_GIVEN,
    LIKELIHOOD_REASON,
    _likelihood,
    _param_results,
    _series_notes,
    _si_result,
    _stats,
    neg2loglik,
)
from ...io.dataset import Dataset, check_dataset_like
from ...io.noise import ratio_pvalue
from ..diagnostics.goodness import SHARPEN_BELOW, combine, f_pvalue, goodness
from ..diagnostics.identifiability import find_structure, jacobian, jacobian_errors, make_verdict
from ..diagnostics.plausibility import check_plausibility
from .predict import (
    PREDICTORS,
    SCENE_QUANTITIES,
    SkipDataset,
    Target,
    get_scene_quantity,
    make_target,
    predict,
    register_predictor,
    set_scene_quantity,
    takes_rtol,
)
from ...core.fpstate import with_own_errstate
from ...solve.choice import applicable_solvers, auto_solver

__all__ = ["DatasetFit", "FitResult", "ParamResult", "PREDICTORS", "SCENE_QUANTITIES", "SkipDataset", "Stats", "Target",
           "applicable_solvers", "auto_solver", "fit", "get_scene_quantity", "law_values", "make_target", "predict",
           "register_predictor", "scene_ranges", "set_scene_quantity"]
if TYPE_CHECKING:  # annotations only
    from ...physics.law import FrictionLaw
    from .predict import DatasetLike

_KEEP = (ODE_STARTS, PENALTY, LIKELIHOOD_REASON, neg2loglik)  # re-exported names other modules read from here


@with_own_errstate
def law_values(law, values: Mapping[str, object] | None, where: str) -> dict[str, float]:
    """Law parameter values by name in SI, each given as an SI number, a quantity string or a pint Quantity;
    an unknown name or a wrong unit is an error naming ``where``, the parameter and the unit expected."""
    if values is None:
        return {}
    if not isinstance(values, Mapping):
        raise TypeError(f"{where}: expected a mapping of parameter names to values, got {type(values).__name__}")
    return {name: as_si(v, law.spec(name).unit, f"{where}: {name}") for name, v in values.items()}


def scene_ranges(free: Mapping[str, object] | None, where: str) -> dict[str, tuple[float, ...]]:
    """Freed scene quantities by name as SI bounds (lower, upper[, start]); each is given as 'low:high[:start]'
    with units, or a tuple of two or three values in any form (``core.units.as_range``)."""
    if free is None:
        return {}
    if not isinstance(free, Mapping):
        raise TypeError(f"{where}: expected a mapping of scene quantities to bounds, got {type(free).__name__}")
    out = {}
    for name, bounds in free.items():
        if name not in SCENE_QUANTITIES:
            raise ParameterError(f"{where}: {name!r} is not a scene quantity; choose from {', '.join(SCENE_QUANTITIES)}")
        out[name] = as_range(bounds, SCENE_QUANTITIES[name], f"{where}: {name}")
    return out


@one_blas_thread
def fit(law: str | FrictionLaw, datasets: DatasetLike | Sequence[DatasetLike], solver: str = "auto", *, free: Mapping[str, object] | None = None,
        fixed: Mapping[str, object] | None = None, local: Sequence[str] = (),
        initial: Mapping[str, object] | None = None, observable: str | None = None, derive: str | None = None,
        scan: int = 125, n_starts: int = 3, max_nfev: int | None = None, rtol: float | None = None,
        timeout: float | None = None, checks: bool = True, errors: bool = True, n_params: int | None = None,
        progress: Callable[[int, int, str], None] | None = None, trend: bool | None = None,
        stiffness: bool | None = None, noise: Sequence | None = None) -> FitResult:
    """Fit ``law`` to one dataset or a group of them (a global fit) and return a FitResult.

    A built-in rate-and-state law on quasi-static spring-slider datasets (solver "auto" or "ode", no
    ``local``) is fitted as the field fits velocity steps (``inference.velstep.fit``): the slider in its own
    variables, mu0 and a friction-versus-displacement trend by variable projection, the machine stiffness
    fitted, a global start, AR(1) noise or the AR(p) model the data choose where the dataset declares it.

    Parameters
    ----------
    law : str or FrictionLaw
        A registered name or a law.
    datasets : Dataset, str, path or Target, or a sequence of them
        One dataset, or several fitted together with shared law parameters.
    solver : str, default "auto"
        ``"auto"`` (exact where a closed form exists, else the ODE), ``"exact"``, ``"series"``,
        ``"ode[:METHOD]"``.
    free : mapping, optional
        Scene quantities fitted per dataset, name -> bounds: ``"low:high[:start]"`` with units, or
        ``(lower, upper[, start])`` of SI numbers, quantity strings or pint Quantities (``u0`` [m/s], ...).
    fixed, initial : mapping, optional
        Law parameters held for every dataset (on top of each dataset's ``[fixed]``), and start values; each
        value an SI number, a quantity string or a pint Quantity.
    local : sequence of str, default ()
        Law parameters fitted separately per dataset in a global fit.
    observable : str, optional
        The column to fit (default the dataset's observable); see `make_target`.
    derive : {"poly9", "spline"}, optional
        Fit omega derived from the theta column by this smoother.
    scan : int, default 125
        Grid points scored before Levenberg-Marquardt (0: start from the defaults).
    n_starts : int, default 3
        Levenberg-Marquardt runs from the best distinct grid points (the lowest chi-square wins).
    max_nfev : int, optional
        Most model evaluations per run.
    rtol : float, optional
        Relative (and scaled absolute) tolerance of every ODE solve in the fit, in (0, 1); None: 1e-6.
        Closed forms and the series ignore it.
    timeout : float, optional
        Time budget of the fit [s]; past it the fit is "failed".
    checks, errors : bool, default True
        False skips the plausibility flags, or the error analysis beyond lmfit's: for replicate refits that
        read only values and the chi-square.
    n_params : int, optional
        With ``errors=False``, the number of parameters the criteria and tests count.
    progress : callable, optional
        ``progress(done, total, label)``, told each stage and its count of model evaluations.
    trend, stiffness : bool, optional
        For velocity steps: fit (True) or hold (False) the friction-displacement trend and the machine
        stiffness; None fits them on measured data.
    noise : sequence, optional
        For velocity steps: None uses the noise the dataset declares; a fit's per-dataset ``noise_state`` holds
        that noise model (as a refit to a noise-free curve needs).

    Returns
    -------
    FitResult
        Values with standard errors (SI), the statistics, the goodness-of-fit verdict, identifiability
        warnings and notes; ``status`` is "failed" or "skipped" with a ``reason`` when the fit could not run.

    Raises
    ------
    FrictionLabError
        An unknown law, parameter or dataset, a value outside its bounds, or a quantity in the wrong unit.

    Examples
    --------
    >>> import frictionlab as fl
    >>> r = fl.fit("wear", "impact-golf-v28", solver="series")
    >>> r.goodness.fits, f"{r.value('lam'):.3g} Pa s/m"
    (True, '1.79e+06 Pa s/m')
    """
    import lmfit  # slow to import: only when fitting

    beat()  # in a child of inference.fitting.guard, this fit's time budget counts from now
    check_type(solver, str, "fit: solver", "a solver name such as 'auto', 'exact' or 'ode'")
    law = get_law(law)
    clock = (time.perf_counter(), time.thread_time())
    items = as_items(datasets, "fit: datasets")
    if not items:
        raise DatasetError("fit: no datasets given")
    names = tuple(d.name if hasattr(d, "name") else str(d) for d in items)  # str() of a Target prints its arrays

    def give_up(status, reason, **kw):
        return FitResult(law=law.name, solver=solver, datasets=names, status=status, reason=reason,
                         wall_time=time.perf_counter() - clock[0], cpu_time=time.thread_time() - clock[1], **kw)

    for d in items:  # a dataset argument as given, and a Dataset still what loading made of it
        check_dataset_like(d, "fit: datasets", (Target,))
        if isinstance(d, Dataset):
            d.check("fit")
    try:
        targets = [d if isinstance(d, Target) else make_target(d, observable, derive) for d in items]
    except SkipDataset as exc:
        return give_up("skipped", str(exc))
    names = tuple(t.name for t in targets)
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:  # its points would count twice and the error bars shrink by sqrt(2)
        raise DatasetError(f"fit: dataset '{twice[0]}' is given more than once; give each dataset once")
    fixed, initial = law_values(law, fixed, "fit: fixed"), law_values(law, initial, "fit: initial")
    free = scene_ranges(free, "fit: free")
    _check_arguments(law, fixed, local, initial, rtol, timeout)
    _check_budget(scan, n_starts, max_nfev)
    if n_params is not None and (isinstance(n_params, bool) or not isinstance(n_params, int) or n_params < 0
                                 or errors):
        raise ParameterError(f"fit: n_params must be a whole number >= 0 given with errors=False, got {n_params!r}")
    from ..velstep import fit as velstep

    if velstep.applies(law, targets, solver, local, free):
        return velstep.fit(law, targets, fixed=fixed, free=free, initial=initial, trend=trend, stiffness=stiffness,
                           scan=scan, n_starts=n_starts, max_nfev=max_nfev, rtol=rtol, timeout=timeout, checks=checks,
                           errors=errors, n_params=n_params, progress=progress, names=names, clock=clock, noise=noise)
    if trend is not None or stiffness is not None or noise is not None:
        raise ParameterError("fit: trend, stiffness and noise apply to the velocity-step fit only (a built-in rate-and-state "
                             "law on quasi-static spring-slider datasets, solver 'auto' or 'ode')")
    solvers = _solvers(law, targets, solver, rtol)
    if isinstance(solvers, str):
        return give_up("skipped", solvers)
    slots = _law_slots(law, targets, fixed, set(local), initial)
    slots += _scene_slots(targets, free)
    model = _Model(law, targets, solvers, slots, rtol, None if timeout is None else time.monotonic() + timeout)
    if progress is not None:
        from .progress import FitProgress

        model.progress = FitProgress(progress, f"{law.name} on {', '.join(names)}", scan + n_starts)
    params = _parameters(lmfit, slots, checks)
    varying = [s for s in slots if s.vary]
    n_points = sum(t.y.size for t in targets)
    if n_points < len(varying) + 1:
        return give_up("skipped", f"{', '.join(names)}: {n_points} data point{'s' * (n_points != 1)} for {len(varying)} free parameter"
                                  f"{'s' * (len(varying) != 1)}: a fit needs at least {len(varying) + 1}")
    likelihood = _likelihood(targets)
    found = _run_search(lmfit, model, params, slots, solvers, (scan, n_starts, max_nfev), likelihood, checks, timeout,
                        values_only=not (checks or errors))
    if len(found) == 3:  # (status, reason, extra): failed or skipped
        return give_up(*found[:2], **found[2])
    known = None
    if checks and errors:
        found, known = _polished(lmfit, law, model, slots, found, likelihood not in AS_GIVEN, timeout)
    values, models, best_params, best, outcome = found
    solver_label = solver if solver != "auto" else "+".join(dict.fromkeys(solvers))
    return _result(law, names, solver_label, model, slots, values, models, best_params, best, outcome,
                   likelihood, checks, errors, clock, n_params, known)


def _polished(lmfit, law, model, slots, found, scale_covar: bool, timeout):
    """(``found``, or a better minimum; (J, structure) at its values). Levenberg-Marquardt can stop short of
    the minimum beside a free parameter that has no effect on the prediction there (its Jacobian column
    is zero): the area-rate fit to kharaz2001-tangential-cor stopped at mu = 0.0939, chi-square 27.044,
    where mu = 0.0925 gives 27.021 at the same eta'. Where a Gauss-Newton step in the other free parameters
    predicts a fall in chi-square of more than Levenberg-Marquardt's own tolerance (FTOL), they are refitted
    with those held, then all of them from there; the result is kept, and said in the fit's notes, when it
    lowers chi-square by more than that tolerance. A main fit's step only: replicate refits start from its
    values; at a minimum no evaluation is added."""
    values, models, best_params, best, outcome = found
    J = jacobian(model, slots, values)
    structure = find_structure(law, slots, values, J)
    varying = [s for s in slots if s.vary]
    held = [s for s in varying if s.display in structure["no_effect"]]
    if not held or len(held) == len(varying) or not outcome[0]:
        return found, (J, structure)
    z = np.concatenate([(m - tg.y) / tg.sigma for tg, m in zip(model.targets, models)])
    others = J[:, [i for i, s in enumerate(varying) if s not in held]]
    step = np.linalg.lstsq(others, z, rcond=None)[0]
    if float(np.sum((others @ step) ** 2)) <= FTOL * float(z @ z):  # Gauss-Newton gains nothing: at the minimum
        return found, (J, structure)
    budget = 200 * (len(varying) + 1)
    try:
        with alarm(timeout):
            params = lsrefit.lmfit_parameters(best_params).copy()
            for s in held:
                params[s.pname].set(vary=False)
            first = lmfit_leastsq(lmfit, model, slots, params, scale_covar, budget)
            for s in held:
                first.params[s.pname].set(vary=True)
            r = lmfit_leastsq(lmfit, model, slots, first.params, scale_covar, budget)
    except (FitTimeout, FrictionLabError):
        return found, (J, structure)
    if not (r.success and r.chisqr < best.chisqr * (1 - FTOL)):
        return found, (J, structure)
    values = _si(r.params, slots)
    names = ", ".join(s.display for s in held)
    note = (f"Levenberg-Marquardt stopped short of the minimum beside {names} (no effect on the prediction "
            f"there); refitting the other parameters with {names} held, then all of them, lowered chi-square "
            f"from {best.chisqr:.6g} to {r.chisqr:.6g}")
    J = jacobian(model, slots, values)
    return ((values, model.models(values), r.params, r, (True, str(r.message), list(outcome[2]) + [note])),
            (J, find_structure(law, slots, values, J)))


def _run_search(lmfit, model, params, slots, solvers, budget, likelihood, checks, timeout, values_only=False):
    """The search under the time budget: (SI values, models, parameters, lmfit result, (success, message,
    notes)), or (status, reason, extra) of a fit that failed or is skipped. budget: (scan, n_starts, max_nfev);
    values_only: the caller reads values and chi-square only (``fitmodel._search``)."""
    success, message = True, ""
    try:
        with alarm(timeout):
            best_params, success, message, best, notes = _search(lmfit, model, params, slots, solvers, *budget,
                                                                 scale_covar=likelihood not in AS_GIVEN,
                                                                 direct=not checks, values_only=values_only)
            values = _si(best_params, slots)
            models = model.models(values)
        model.deadline = None  # the error analysis after it is bounded work
    except FitTimeout:
        return "failed", f"exceeded its time budget of {timeout:g} s (--fit-timeout)", {"nfev": model.nfev}
    except SkipDataset as exc:
        return "skipped", str(exc), {}
    except FrictionLabError as exc:  # an aborted search leaves parameters that mean nothing: say it did not converge
        why = f"did not converge: {message}" if not success else f"the model cannot be evaluated at the best parameters: {exc}"
        return "failed", why, {"nfev": model.nfev}
    except Exception as exc:  # an optimizer or law crash is a failed fit, not a crashed comparison
        return "failed", f"{type(exc).__name__}: {exc}", {"nfev": model.nfev}
    return values, models, best_params, best, (success, message, notes)


def _check_arguments(law, fixed, local, initial, rtol, timeout) -> None:
    """Raise the one-line input error for an unknown parameter, a start or held value outside its
    bounds, an rtol outside (0, 1) or a time budget that is no positive number."""
    for name in list(fixed or {}) + list(local) + list(initial or {}):
        law.spec(name)  # unknown names are input errors
    law.resolve({**(initial or {}), **(fixed or {})})  # so are held or start values outside the bounds
    if rtol is not None and (isinstance(rtol, bool) or not isinstance(rtol, (int, float)) or not 0 < rtol < 1):
        raise ParameterError(f"fit: rtol must be a number in (0, 1), got {rtol!r}")
    if timeout is not None and (isinstance(timeout, bool) or not isinstance(timeout, (int, float))
                                or not 0 < timeout < math.inf):
        raise ParameterError(f"fit: timeout must be a positive number of seconds, got {timeout!r}")


def _check_budget(scan, n_starts, max_nfev) -> None:
    """scan a whole number >= 0, n_starts >= 1, max_nfev None or >= 1, else a ParameterError naming it."""
    for name, value, least in (("scan", scan, 0), ("n_starts", n_starts, 1), ("max_nfev", max_nfev, 1)):
        if value is None and name == "max_nfev":
            continue
        if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < least:
            raise ParameterError(f"fit: {name} must be a whole number, at least {least}"
                                 + (" (or None: no limit)" if name == "max_nfev" else "") + f", got {value!r:.40}")


def _solvers(law, targets, solver: str, rtol) -> list[str] | str:
    """The solver of each target, or the reason (a str) why the fit is skipped."""
    solvers = []
    for tg in targets:
        if tg.dataset.kind not in PREDICTORS:
            return f"no predictor for dataset kind '{tg.dataset.kind}' (dataset '{tg.name}')"
        if tg.dataset.scene is None:
            return f"dataset '{tg.name}' has no scene"
        if rtol is not None and not takes_rtol(PREDICTORS[tg.dataset.kind]):
            raise ParameterError(f"fit: rtol given, but the predictor of dataset kind '{tg.dataset.kind}' "
                                 "takes no 'rtol' keyword")
        ok = applicable_solvers(law, tg.dataset.scene)
        s = auto_solver(law, tg.dataset.scene) if solver == "auto" else solver
        base = s.partition(":")[0]
        if base not in ok:
            from ...solve.solvers import parse_solver

            parse_solver(s)  # raises the one-line error for an unknown solver
        if ok.get(base):
            return f"{base} on '{tg.name}': {ok[base]}"
        solvers.append(s)
    return solvers


def _parameters(lmfit, slots, checks: bool):
    """The optimizer's parameters (values / scale): ``lsrefit``'s light ones for replicate refits, lmfit's
    own (and its error where the bounds are no interval) otherwise."""
    bounds = [(lsrefit.lmfit_bound(s.lower, s) / s.scale, lsrefit.lmfit_bound(s.upper, s) / s.scale) for s in slots]
    if not checks and all(lo < hi and (math.isinf(lo) or math.isinf(hi) or hi - lo > 1e-13 + 1e-13 * abs(hi))
                          for lo, hi in bounds):  # an interval lmfit accepts
        return {s.pname: lsrefit.Param(s.pname, s.value / s.scale, lo, hi, s.vary) for s, (lo, hi) in zip(slots, bounds)}
    params = lmfit.Parameters()
    for s, (lo, hi) in zip(slots, bounds):
        params.add(s.pname, value=s.value / s.scale, vary=s.vary, min=lo, max=hi)
    return params


def _result(law, names, solver_label, model, slots, values, models, best_params, best, outcome, likelihood,
            checks, errors, clock, n_params=None, known=None) -> FitResult:
    """The FitResult at the best parameters: per-dataset fits and goodness, statistics, error bars,
    identifiability and plausibility. outcome: (success, message, notes) of the search; known: (Jacobian,
    structure) at ``values`` if already computed."""
    success, message, search_notes = outcome
    targets, varying = model.targets, [s for s in slots if s.vary]
    if model.progress is not None:
        model.progress.stage("error analysis", 2 * len(varying) + 2)
    if errors:
        if known is None:
            J = jacobian(model, slots, values)
            known = (J, find_structure(law, slots, values, J))
        J, structure = known
    else:
        k = len(varying) if n_params is None else int(n_params)
        structure = {"at_bounds": (), "ratios": (), "no_effect": (), "k_eff": k, "n_free": len(varying)}
    per = _per_dataset(model, values, models, structure["k_eff"] / len(targets), J if errors else None)
    chisqr = sum(d.chisqr for d in per)
    stats = _stats(sum(t.y.size for t in targets), structure["k_eff"], len(varying), chisqr, per)
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
    scaled = likelihood not in AS_GIVEN  # error bars from the scatter when sigma means nothing
    jac = (jacobian_errors(slots, values, J, structure, stats.redchi if scaled else 1.0) if errors
           else {"errors": {}, "derived": {}, "correl": {}})
    presults = _param_results(slots, best_params, targets, structure, jac)
    if likelihood == "none":  # error bars rest on independent points: a smoothed series has none to give
        presults = {k: attrs.evolve(p, stderr=None) for k, p in presults.items()}
    if any(t.derivation for t in targets):
        notes.append("fitted to a derived series (omega smoothed from theta): its points are correlated, so no "
                     "chi-square, information criterion or error bar is valid; fit theta itself for those")
    correl = _correlations(slots, varying, best_params, structure, jac)
    flags, numbers, nfev = (), {}, model.nfev  # plausibility's own evaluations are not the fit's
    if status == "ok" and checks:
        if model.progress is not None:
            model.progress.stage("plausibility checks", 1)
        flags, numbers = check_plausibility(law, per, model, slots, values, likelihood)
    if model.progress is not None:
        model.progress.finish(f"{status} after {model.nfev} evaluations")
    return FitResult(law=law.name, solver=solver_label, datasets=names, status=status, reason=reason,
                     params=presults, correlations=correl, stats=stats,
                     identifiability=make_verdict(structure, presults, correl),
                     per_dataset=tuple(per), nfev=nfev, wall_time=time.perf_counter() - clock[0],
                     cpu_time=time.thread_time() - clock[1],
                     message=message, notes=tuple(notes), goodness=combine([d.goodness for d in per]),
                     flags=tuple(flags), plausibility=numbers, minimizer_result=_si_result(best, slots) if checks else None)


def _per_dataset(model, values, models, k_each, J=None) -> list[DatasetFit]:
    """Each target's part of the fit; k_each: a group's parameters shared out for each member's test;
    J: the weighted Jacobian of all targets' points (None: not computed)."""
    per, start = [], 0
    for tg, solver_i, (p, scene), m in zip(model.targets, model.solvers, model.split(values), models):
        r = m - tg.y
        z = r / tg.sigma
        kind, k = _likelihood([tg]), round(k_each)
        est = tg.dataset.noise_est.get(tg.observable) if kind == "estimated" else None
        chi_p = None
        if est is not None:
            chi_p = f_pvalue(float(z @ z), z.size - k, est.df)
            if J is not None and chi_p >= SHARPEN_BELOW:  # conservative: sharpen where it does not already reject
                chi_p = ratio_pvalue(est, float(z @ z), J[start:start + z.size])
        start += z.size
        per.append(DatasetFit(tg, solver_i, p, scene, m, float(r @ r), float(np.sqrt(np.mean(r**2))),
                              float(np.sum(z**2)), goodness(z, k, kind, est.df if est else math.inf, chi_p)))
    return per


def _correlations(slots, varying, best_params, structure, jac) -> dict:
    """Correlations of the free parameters by display name: lmfit's, or the identifiable part's where
    a ratio-only pair or a parameter without effect makes lmfit's covariance degenerate."""
    if structure["ratios"] or structure["no_effect"]:
        return jac.get("correl", {})
    correl = {}
    for s in varying:
        for other, r in (best_params[s.pname].correl or {}).items():
            o = next(x for x in slots if x.pname == other)
            if s.display < o.display:
                correl[(s.display, o.display)] = float(r)
    return correl
