"""The velocity-step fit: a rate-and-state law fitted to spring-slider records as the field fits them.

``fitting.fit`` hands a fit here when the law is a built-in one of ``quasistatic.FITTED`` (aging, slip, PRZ,
Nagata), every dataset is a spring-slider whose slider is quasi-static (``solve.quasistatic.applies``), the
solver is 'auto' or 'ode' and no law parameter is fitted per dataset ('local'). The result is the usual
``FitResult``.

Model of dataset i, in laboratory units (t in s, displacements in um):

    mu_obs(t) = mu_ss,i + m(t; a, b, Dc, k_i) + s_i (x(t) - x_ref,i)     (Nagata's law: m(t; a, b, Dc, c, k_i))

m = mu - mu_ss(V1) of the quasi-static slider (``solve.quasistatic``: steady state at the first load-point
velocity V1 until the first step, then through every step and hold of ``[scene.spring]``), x the load-point
displacement (the dataset's x column, else the schedule's) and x_ref its value at the first step.

* Nonlinear parameters: a, b and Dc (and Nagata's c, seen as itself, within the law's bounds, 0 the aging law)
  shared by the datasets, and the machine stiffness k_i of each: fitted by default on measured data (a start: the dataset's stiffness), held at the dataset's value elsewhere, or as
  ``free={'spring.stiffness': (lo, hi)}`` says. Levenberg-Marquardt with bounds (``Problem.lm``; the laws'
  bounds for a, b, Dc) sees a / 0.01, b / 0.01 (Nagata's b, kept above 0: its softplus, ln b at small b,
  ``velstep.params``), ln Dc and ln k, and the normal equations of the forward sensitivities, summed in one
  compiled pass over the samples (``velstep_kernel``).
* Linear parameters, by variable projection (Golub and Pereyra 1973): mu_ss,i and the trend s_i are solved by
  linear least squares inside every evaluation (the residual is projected off their columns; as those do
  not depend on the nonlinear parameters, the projected sensitivities are the exact Jacobian). The trend is
  fitted by default on measured data (``trend``: None, True or False). The reported covariance is the full one
  of every parameter fitted jointly; the law's mu0 (at V0 = 1 um/s) is mu_ss - (a - b) ln(V1 / V0).
* Global start: a grid over ln Dc (and ln k where it is fitted), a, b (and c) fitted at each grid point on at most
  SEARCH_POINTS samples, full fits from the best distinct grid points on that subsample, and the lowest one
  then fitted on every sample. For Nagata's law the grid runs again with c = 0 (the aging law it extends), and
  the best of that grid gets its own full fit: the lower of the two full fits is kept.
* Noise: the dataset's sigma (known or estimated), or, where it declares ``correlation = "ar1"``, the AR(1)
  model of ``inference.noise.ar1``: the fit and phi's profile alternate until phi settles; where it declares
  ``correlation = "arp"``, the data's AR(p) / ARMA(1,1) model per rate group (``noise.record``), chosen from the
  fit's residuals with its innovation level profiled, alternating with the fit (feasible GLS) until the models
  stay the same and the levels settle (``velstep.series``).

``velstep_result.build`` turns the fitted problem into the FitResult (parameters, statistics, goodness of fit,
identifiability with what a bound means, the parameter table in laboratory units).
"""
from __future__ import annotations

import math
import time

import attrs
import numpy as np

from ...core.errors import FrictionLabError, SolverError
from ...solve import quasistatic
from ...solve.quasistatic import UM, Load
from ..fitting.alarm import FitTimeout
from .params import AB_SCALE, B_KNEE, Param, with_value
from .series import SEARCH_DENSE, SEARCH_POINTS, Series  # noqa: F401  (the fit's public names)

#: Grid of the global start: points along ln Dc, and along ln k where k is fitted (its span: start / K_SPAN to
#: start * K_SPAN); Levenberg-Marquardt iterations of a and b at each grid point.
GRID_DC, GRID_K, K_SPAN, SEARCH_ITERS = 8, 5, 30.0, 6
#: Bounds of a fitted stiffness without given bounds: its start divided and multiplied by this factor.
K_BOUNDS = 1e3
#: Tolerance of the integrations of the search and of the fit (``rtol`` of fit() overrides the latter).
SEARCH_RTOL, FIT_RTOL = 1e-5, 1e-8
#: Largest number of fit / phi-profile alternations, and the change in phi below which they stop.
AR1_ROUNDS, AR1_TOL = 8, 1e-3
#: Columns every Jacobian column combines (``velstep_kernel``): the sensitivities to a, b, Dc and k, and a constant
#: (then those to a law's ``quasistatic.EXTRA`` parameters).
NBASIS = 5


def applies(law, targets, solver: str, local, free) -> bool:
    """Whether this fit serves ``law`` on ``targets`` (module docstring)."""
    if solver not in ("auto", "ode") or local:
        return False
    if set(free or {}) - {"spring.stiffness"}:
        return False
    if law.name not in quasistatic.FITTED:
        return False
    return all(tg.dataset.kind == "spring-slider" and tg.observable == "mu" and not tg.derivation
               and tg.t is not None and not quasistatic.applies(law, tg.dataset.scene) for tg in targets)


class Problem:
    """The least-squares problem of the velocity-step fit: nonlinear parameters, datasets, their evaluation."""

    def __init__(self, law, targets, params: list[Param], series: list[Series], rtol: float, deadline=None,
                 progress=None):
        self.law, self.targets, self.params, self.series = law, targets, params, series
        self.code = quasistatic.LAWS[law.name]
        self.extra = quasistatic.EXTRA.get(self.code, ())
        self.rtol, self.deadline, self.progress = rtol, deadline, progress
        self.free = [i for i, p in enumerate(params) if p.vary]
        self.nfev = 0
        self.failures = 0
        self.last_error = ""
        self._cache = None
        #: The grid points of the last ``search`` whose a, b fit ended with b held at its lower bound (best first):
        #: where a refit that lets b go lower starts (``velstep_result``).
        self.b_held: list[np.ndarray] = []

    # -- parameters -----------------------------------------------------------------------------------------
    def x_start(self) -> np.ndarray:
        return np.array([p.to_x(p.value) for p in self.params])

    def values(self, x) -> dict:
        """Laboratory values: {'a', 'b', 'Dc' [um], 'k': [1/um per dataset], and an extra law parameter such as
        'c'} at the full parameter vector x."""
        v = {"k": [0.0] * len(self.series)}
        for p, xi in zip(self.params, x):
            if p.key == "k":
                v["k"][p.target] = p.from_x(xi)
            else:
                v[p.key] = p.from_x(xi)
        return v

    def bounds(self, free) -> tuple[np.ndarray, np.ndarray]:
        lo, hi = zip(*(self.params[i].bounds_x for i in free))
        return np.array(lo), np.array(hi)

    # -- evaluation -----------------------------------------------------------------------------------------
    def evaluate(self, x, free, search: bool = False, rtol: float | None = None):
        """(chi-square r'r, J'r, J'J, solved) of the weighted, prewhitened, projected residual r and its Jacobian J by
        the parameters ``free`` at the full vector x (``velstep_kernel``: nothing per sample is kept); a model
        that cannot be solved there gives (inf, 0, 0, False)."""
        from .kernel import all_sums

        key = (np.asarray(x).tobytes(), tuple(free), search, rtol)
        if self._cache is not None and self._cache[0] == key:
            return self._cache[1]
        if self.deadline is not None and time.monotonic() > self.deadline:
            raise FitTimeout()
        self.nfev += 1
        if self.progress is not None:
            self.progress.tick()
        v = self.values(x)
        p = len(free)
        cost, g, A = 0.0, np.zeros(p), np.zeros((p, p))
        try:
            for s in self.series:
                sol = self.solve(v, s, s.t_search if search else s.t,
                                 rtol or (SEARCH_RTOL if search else self.rtol), True)
                M = self.combination(s, v, free)
                if search:  # white noise on the subsample
                    sums = all_sums(s.y_ref_search, s.offset(v["a"], v["b"]), sol.m, sol.S, s.inv_sigma_search,
                                      s.no_phi, s.no_phi, s.Q_search)
                elif s.arp:
                    sums = s.whitened_sums(s.offset(v["a"], v["b"]), sol.m, sol.S)
                else:
                    sums = all_sums(s.y_ref, s.offset(v["a"], v["b"]), sol.m, sol.S, s.inv_sigma, s.phi, s.gain,
                                      s.Q)
                ww, Bw, BB, Qw, QB = sums
                QC = QB @ M
                cost += ww - float(Qw @ Qw)
                g += M.T @ Bw - QC.T @ Qw
                A += M.T @ BB @ M - QC.T @ QC
            out = (cost, g, A, bool(np.isfinite(cost)))
        except SolverError as exc:
            self.failures += 1
            self.last_error = str(exc)
            out = (math.inf, g, A, False)
        self._cache = (key, out)
        return out

    def solve(self, v, s: Series, t, rtol: float, sensitivities: bool = False):
        """The quasi-static slider of dataset s at the laboratory values v (``values``) at times t."""
        return quasistatic.solve(self.code, v["a"], v["b"], v["Dc"], v["k"][s.index], s.load, t, rtol,
                                 sensitivities=sensitivities, c=v.get("c", 0.0))

    def combination(self, s: Series, v, free) -> np.ndarray:
        """M ((5 + extra) x len(free)): the columns d(model)/d(x_j) of the parameters ``free`` on dataset s are
        [S[:, :4], 1, S[:, 4:]] M, with S = dm/d(a, b, Dc, k, extra) the sensitivities (a zero column for another
        dataset's stiffness)."""
        held = s.L1 if s.mu0 is not None else 0.0  # a held mu0 at V0 puts (a - b) ln(V1 / V0) in the model
        M = np.zeros((NBASIS + len(self.extra), len(free)))
        for j, i in enumerate(free):
            p = self.params[i]
            if p.key == "a":
                M[0, j], M[4, j] = AB_SCALE, held * AB_SCALE
            elif p.key == "b":
                d = p.slope_at(v["b"])
                M[1, j], M[4, j] = d, -held * d
            elif p.key == "Dc":
                M[2, j] = v["Dc"]
            elif p.key in self.extra:
                M[NBASIS + self.extra.index(p.key), j] = p.scale
            elif p.target == s.index:  # this dataset's stiffness
                M[3, j] = v["k"][s.index]
        return M

    def columns(self, s: Series, v, x, S, free) -> np.ndarray:
        """d(model)/d(x_j) for the parameters ``free`` on dataset s, from the sensitivities S = dm/d(a, b, Dc, k,
        extra)."""
        return np.column_stack([S[:, :4], np.ones(S.shape[0]), S[:, 4:]]) @ self.combination(s, v, free)

    def model(self, x) -> list[np.ndarray]:
        """Each dataset's model of mu (linear parameters solved) at the full vector x, every sample."""
        v = self.values(x)
        out = []
        for s in self.series:
            sol = self.solve(v, s, s.t, self.rtol)
            m = s.offset(v["a"], v["b"]) + sol.m
            out.append(m + s.B @ s.linear(v["a"], v["b"], sol.m))
        return out

    # -- fitting ---------------------------------------------------------------------------------------------
    def local(self, x0, free, search: bool = False, max_nfev: int | None = None, tol: float = 1e-10):
        """Levenberg-Marquardt with bounds over the parameters ``free`` from the full vector x0 (``lm``)."""
        return self.lm(x0, free, search, max_nfev or 100 * (len(free) + 1), tol)

    def damped(self, x0, free):
        """The grid's inner fit (of a and b): a few Levenberg-Marquardt steps on the search subsample."""
        return self.lm(x0, free, True, SEARCH_ITERS, 1e-6)

    def lm(self, x0, free, search: bool, max_nfev: int, tol: float):
        """Levenberg-Marquardt (Marquardt's scaling by the diagonal of J'J) with bounds: a parameter at a bound
        whose gradient points outward is held for the step (an active set), a step is clipped into the box.
        Stops when a step lowers chi-square by less than ``tol`` relative and moves every parameter by less than
        sqrt(tol) (relative, or absolute below 1), or after ``max_nfev`` evaluations. Returns (x, cost = chi2 / 2,
        success)."""
        x = np.array(x0, dtype=float)
        if not free:
            cost, _, _, ok = self.evaluate(x, free, search)
            return x, 0.5 * cost, ok
        lo, hi = self.bounds(free)
        z = np.clip(x[free], lo, hi)
        x[free] = z
        cost, g, A, ok = self.evaluate(x, free, search)
        if not ok:
            return x, math.inf, False
        lam, used = 1e-3, 1
        while used < max_nfev:
            out = ((z <= lo) & (g > 0)) | ((z >= hi) & (g < 0))
            f = np.nonzero(~out)[0]
            if not f.size:
                break
            Af = A if f.size == z.size else A[np.ix_(f, f)]
            d = np.diag(Af).copy()
            d[d <= 0] = 1e-12 * max(float(d.max()), 1e-300)
            try:
                step = np.linalg.solve(Af + lam * np.diag(d), -g[f])
            except np.linalg.LinAlgError:
                lam *= 10
                continue
            trial = z.copy()
            trial[f] = np.clip(z[f] + step, lo[f], hi[f])
            x_t = x.copy()
            x_t[free] = trial
            c_t, g_t, A_t, ok_t = self.evaluate(x_t, free, search)
            used += 1
            if ok_t and c_t < cost:
                small = np.all(np.abs(trial - z) <= math.sqrt(tol) * np.maximum(1.0, np.abs(z)))
                done = (cost - c_t) <= tol * cost and small
                x, z, g, A, cost, lam = x_t, trial, g_t, A_t, c_t, max(lam / 3, 1e-12)
                if done:
                    break
            else:
                lam *= 4
                if lam > 1e10:
                    break
        return x, 0.5 * cost, True

    def search(self, n_starts: int) -> list[list[np.ndarray]]:
        """Starts for the full fit, in groups: the given start and the best distinct points of a grid over ln Dc
        (and ln k of each fitted stiffness, jointly scaled), with a and b fitted at each on the search subsample.
        A law with an extra parameter (Nagata's c) has a second group from the same grid with the parameter at
        its lower bound, where the law is the one it extends (c = 0: the aging law): a basin the first grid can
        miss, and one the subsample can misjudge, so each group gets its own full fit (``_solve``)."""
        x0 = self.x_start()
        by_key = {p.key: i for i, p in enumerate(self.params) if p.target < 0}
        nested = [(by_key[k], self.params[by_key[k]].bounds_x[0]) for k in self.extra if self.params[by_key[k]].vary]
        grids = [self._grid(x0, by_key)] + [self._grid(with_value(x0, i, lo), by_key) for i, lo in nested]
        b_low = self.params[by_key["b"]].bounds_x[0]
        held = sorted((c for g in grids for c in g if c[3][by_key["b"]] <= b_low), key=lambda c: c[0])
        self.b_held = _distinct(held, n_starts) if self.params[by_key["b"]].vary else []
        return [[x0] + _distinct(grids[0], n_starts)] + [_distinct(g, n_starts) for g in grids[1:] if g]

    def _grid(self, x0, by_key) -> list[tuple]:
        """The grid of ``search`` around x0: (cost, Dc index, k index, x) of each point whose a, b fit succeeded,
        lowest cost first."""
        iDc = by_key["Dc"]
        ks = [i for i, p in enumerate(self.params) if p.key == "k" and p.vary]
        ab = [by_key[k] for k in ("a", "b") + self.extra if self.params[by_key[k]].vary]
        dcs = _dc_grid(self.series, self.params[iDc]) if self.params[iDc].vary else [self.params[iDc].value]
        kf = np.geomspace(1 / K_SPAN, K_SPAN, GRID_K) if ks else np.ones(1)
        scored = []
        for a_i, Dc in enumerate(dcs):
            for b_i, f in enumerate(kf):
                x = x0.copy()
                x[iDc] = self.params[iDc].to_x(Dc)
                for i in ks:
                    p = self.params[i]
                    x[i] = p.to_x(float(np.clip(p.value * f, p.lower, p.upper)))
                x, cost, ok = self.damped(x, ab)
                if ok:
                    scored.append((cost, a_i, b_i, x))
        scored.sort(key=lambda c: c[0])
        return scored


def _distinct(scored, n: int) -> list[np.ndarray]:
    """The best ``n`` of the scored grid points (cost, Dc index, k index, x; sorted by cost), each at least two grid
    steps from those taken before it along Dc or k."""
    out, taken = [], []
    for _, a_i, b_i, x in scored:
        if len(taken) >= n:
            break
        if all(abs(a_i - a) >= 2 or abs(b_i - b) >= 2 for a, b in taken):
            out.append(x)
            taken.append((a_i, b_i))
    return out


def _slip_after_step(target) -> float:
    """Load-point slip [um] from the first step (or the start) to the last sample of ``target``."""
    load = Load.of(target.dataset.scene.spring)
    first = load.times[1] if load.times.size > 1 else 0.0
    return float(load.displacement(target.t[-1]) - load.displacement(first))


def _dc_grid(series, p: Param) -> np.ndarray:
    """Dc [um] candidates: log-spaced from a few samples' worth of slip at the fastest load point to a third of the
    slip after the first step, within the law's bounds."""
    lo, hi = [], []
    for s in series:
        dt = float(np.median(np.diff(s.t))) if s.n > 1 else 1.0
        vmax = float(np.max(s.load.velocities))
        lo.append(3 * vmax * dt)
        first = s.load.times[1] if s.load.times.size > 1 else 0.0
        hi.append((s.load.displacement(s.t[-1]) - s.load.displacement(first)) / 3)
    a, b = max(min(lo), p.lower * 10), min(max(hi), p.upper / 3)
    if not b > a:
        a, b = max(p.lower, 1e-2), max(p.lower * 10, 1e3)
    return np.geomspace(a, b, GRID_DC)


def fit(law, targets, *, fixed=None, free=None, initial=None, trend=None, stiffness=None, scan: int = 125,
        n_starts: int = 3, max_nfev=None, rtol=None, timeout=None, checks: bool = True, errors: bool = True,
        n_params=None, progress=None, names=(), clock=None, noise=None):
    """The velocity-step fit of ``law`` to ``targets`` (module docstring); arguments as ``fitting.fit``, plus
    trend (None: fitted on measured data), stiffness (None: fitted on measured data unless ``free`` names it;
    False: held; True: fitted within K_BOUNDS of its start) and noise (None: the datasets' noise models; else one
    ``VelstepFit.noise_state`` per dataset, held: the noise model of a fit whose curve is refitted). Returns a
    FitResult."""
    from ..fitting.result import FitResult
    from .result import build

    clock = clock or (time.perf_counter(), time.thread_time())
    deadline = None if timeout is None else time.monotonic() + timeout

    def give_up(status, reason, nfev=0):
        return FitResult(law=law.name, solver="ode", datasets=tuple(names), status=status, reason=reason, nfev=nfev,
                         wall_time=time.perf_counter() - clock[0], cpu_time=time.thread_time() - clock[1])

    problem = make_problem(law, targets, fixed or {}, free or {}, initial or {}, trend, stiffness,
                           FIT_RTOL if rtol is None else rtol, deadline)
    for s, state in zip(problem.series, noise or ()):
        s.hold_noise(state)
    n_free = len(problem.free) + sum(s.B.shape[1] for s in problem.series)
    n_points = sum(s.n for s in problem.series)
    if n_points < n_free + 1:
        return give_up("skipped", f"{', '.join(names)}: {n_points} data points for {n_free} free parameters: a fit "
                                  f"needs at least {n_free + 1}")
    if progress is not None:
        from ..fitting.progress import LM_EVALS, FitProgress

        grids = 1 + sum(p.key in problem.extra and p.vary for p in problem.params)  # ``Problem.search``
        grid = GRID_DC * (GRID_K if any(p.key == "k" and p.vary for p in problem.params) else 1) * SEARCH_ITERS * grids
        local = LM_EVALS * (min(n_starts, 3) + 2)  # the starts' fits on the subsample and the full fit
        problem.progress = FitProgress(progress, f"{law.name} on {', '.join(names)}", 1)
        if scan and problem.free:
            problem.progress.stage("velocity-step fit: grid start", grid, total=grid + local)
        else:
            problem.progress.stage("velocity-step fit: local fit", LM_EVALS, total=LM_EVALS)
    try:
        x, cost, ok, rounds = _solve(problem, scan, n_starts, max_nfev)
    except FitTimeout:
        return give_up("failed", f"exceeded its time budget of {timeout:g} s (--fit-timeout)", problem.nfev)
    except Exception as exc:  # a numerical failure is a failed fit, not a crashed comparison
        return give_up("failed", f"{type(exc).__name__}: {exc}", problem.nfev)
    problem.deadline = None
    if not ok:
        return give_up("failed", f"did not converge: {problem.last_error or 'no start could be solved'}",
                       problem.nfev)
    if progress is not None:
        problem.progress.finish(f"done after {problem.nfev} evaluations")
    return build(problem, x, rounds, checks=checks, errors=errors, n_params=n_params, clock=clock, names=names)


def _solve(problem: Problem, scan: int, n_starts: int, max_nfev):
    """The search, the full fits from its starts, then the alternation with phi's profile: (x, cost, success,
    rounds of the alternation)."""
    free = problem.free
    groups = problem.search(max(1, min(n_starts, 3))) if scan and free else [[problem.x_start()]]
    if problem.progress is not None and sum(map(len, groups)) > 1:
        from ..fitting.progress import LM_EVALS

        size = LM_EVALS * sum(len(g) + 1 for g in groups)
        problem.progress.stage("velocity-step fit: local fits", size, total=problem.progress.done + size,
                               other_kind=True)
    best = None
    for starts in groups:  # per group: each start fitted on the search's subsample, the best then on every sample
        if len(starts) > 1:
            found = [problem.local(x0, free, search=True, max_nfev=max_nfev) for x0 in starts]
            found = [f for f in found if f[2]]
            starts = [min(found, key=lambda f: f[1])[0]] if found else starts[:1]
        fitted = problem.local(starts[0], free, max_nfev=max_nfev)
        if fitted[2] and (best is None or fitted[1] < best[1]):
            best = fitted
    if best is None:
        return problem.x_start(), math.inf, False, 0
    x, cost, ok = best
    rounds = 0
    if any(s.correlated and not s.held for s in problem.series):
        for rounds in range(1, AR1_ROUNDS + 1):
            models = problem.model(x)
            change = max(s.set_noise(m - s.y) for s, m in zip(problem.series, models) if s.correlated and not s.held)
            problem._cache = None
            x, cost, ok = problem.local(x, free, max_nfev=max_nfev)
            if not ok:
                return x, cost, False, rounds
            if change < AR1_TOL:
                break
    return x, cost, ok, rounds


def make_problem(law, targets, fixed, free, initial, trend, stiffness, rtol, deadline=None) -> Problem:
    """The Problem of fitting ``law`` to ``targets`` (module docstring): parameters with their starts and bounds,
    and each dataset prepared."""
    held = {}
    extra = quasistatic.EXTRA.get(quasistatic.LAWS[law.name], ())
    for name in ("mu0", "a", "b", "Dc") + extra:
        if name in fixed:
            held[name] = (float(fixed[name]), "held by the caller")
            continue
        vals = {float(tg.dataset.fixed[name]) for tg in targets if name in tg.dataset.fixed}
        if vals and len(vals) == 1 and all(name in tg.dataset.fixed for tg in targets):
            held[name] = (vals.pop(), f"[fixed] in dataset {targets[0].name}" if len(targets) == 1
                          else "[fixed] in every dataset")
        elif vals:
            raise FrictionLabError(f"law '{law.name}': '{name}' is held by some datasets and not by others; the "
                                   "velocity-step fit shares it (fit them separately, or with solver 'ode:LSODA')")
    params = []
    for name, unit in (("a", 1.0), ("b", 1.0), ("Dc", UM)) + tuple((e, 1.0) for e in extra):
        spec = law.spec(name)
        value = held[name][0] if name in held else float(initial.get(name, spec.default))
        lo, hi = spec.lower / unit, spec.upper / unit
        if name == "Dc":  # an evolution longer than the record's slip after its first step is a trend, not a Dc
            lo, hi = max(lo, 1e-6), min(hi, max(_slip_after_step(tg) for tg in targets))
        how = "log" if name == "Dc" else "softplus" if name == "b" and lo > 0 else "lin"  # ``params``
        params.append(Param(name, name, -1, how, value / unit, lo, hi, name not in held, held.get(name, (0, ""))[1],
                            B_KNEE if how == "softplus" else AB_SCALE if name in ("a", "b") else spec.scale))
    series = []
    multi = len(targets) > 1
    for i, tg in enumerate(targets):
        measured = tg.dataset.provenance.kind == "measured"
        s = Series(tg, i, measured if trend is None else bool(trend), held.get("mu0", (None,))[0])
        series.append(s)
        k0 = tg.dataset.scene.spring.stiffness * UM
        name = "spring.stiffness" + (f"[{tg.name}]" if multi else "")
        if "spring.stiffness" in free:
            b = free["spring.stiffness"]
            lo, hi = float(b[0]) * UM, float(b[1]) * UM
            start = float(b[2]) * UM if len(b) == 3 else min(max(k0, lo), hi)
            params.append(Param(name, "k", i, "log", start, lo, hi, True))
        elif stiffness or (stiffness is None and measured):
            params.append(Param(name, "k", i, "log", k0, k0 / K_BOUNDS, k0 * K_BOUNDS, True))
        else:
            params.append(Param(name, "k", i, "log", k0, k0, k0, False, "the dataset's stiffness"))
    for p in params:
        if p.vary and not p.lower < p.upper:
            raise FrictionLabError(f"{p.name}: empty range [{p.lower:g}, {p.upper:g}]")
    params = [attrs.evolve(p, value=min(max(p.value, p.lower), p.upper)) if p.vary else p for p in params]
    return Problem(law, targets, params, series, rtol, deadline)
