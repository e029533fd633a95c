"""The velocity-step fit's result: the FitResult of a fitted ``velstep.Problem``, and what it says in the field's
units (``StepReport``).

* Error bars: the full covariance of every parameter fitted jointly (nonlinear and linear), from the prewhitened
  Jacobian at the noise the likelihood uses, not rescaled (the noise is measured or estimated without the law,
  as for every fit). A parameter at a bound gets no error bar; the others' are then those with it held there.
* Bounds: a parameter within AT_BOUND (relative) of a bound is reported at it, with what that means for these
  data (``BOUND_MEANING``).
* The sign of a - b and the trend: where a trend is fitted, the result says whether the sign of a - b depends on
  it: when |s| times the slip over the record exceeds |a - b| ln(V2/V1) at the largest step, or when a refit
  without the trend gives a - b of the other sign.
* What the data show that the law misses, where it does not fit: a trend it was not given (a refit with one
  lowers chi-square beyond the 0.1 % point of chi-square with one degree of freedom), a strengthening evolution
  (b pressed to 0: a refit that lets b go below 0, from the fit and the search's grid points where the bound held
  b at 0), and residual structure after a step (runs of same-sign mean residual in windows of slip,
  each beyond MISSING_Z standard errors of a mean of correlated noise): slower than the fitted evolution, a
  second state variable.
"""
from __future__ import annotations

import math
import time

import attrs
import numpy as np

from ...solve.quasistatic import UM
from ..noise import ar1
from ..fitting.result import DatasetFit, FitResult, ParamResult, Stats
from ..fitting.stats import LIKELIHOOD_REASON
from ..diagnostics.goodness import SHARPEN_BELOW, combine, f_pvalue, goodness, ljung_box
from ..diagnostics.identifiability import make_verdict

#: A parameter within this distance of a bound (in its optimizer coordinate: a / 0.01, b / 0.01, ln Dc, ln k;
#: relative for the last two) is at the bound.
AT_BOUND = 1e-3
#: Residual windows after a step beyond this many standard errors count as structure the law misses.
MISSING_Z = 4.0
CHI2_1_999 = 10.828  # the 0.1 % point of chi-square with one degree of freedom
REFIT_EVALS = 40  # evaluations on every sample of a diagnostic refit (after it converged on the subsample)

#: What a parameter at a bound means on velocity-step data: (key, 'lower' | 'upper') -> sentence.
BOUND_MEANING = {
    ("b", "lower"): "b at 0: the evolution runs the other way; a single-state law cannot follow it",
    ("b", "upper"): "b at its upper bound: the evolution effect is larger than the law allows",
    ("a", "lower"): "a at its lower bound: no direct effect is resolved (the step is not sampled fast enough)",
    ("a", "upper"): "a at its upper bound: the direct effect is larger than the law allows",
    ("Dc", "lower"): "Dc at its lower bound: the evolution is faster than the sampling resolves",
    ("Dc", "upper"): "Dc at its upper bound (the record's slip after the step): the evolution is slower than the "
                     "record is long, and cannot be told from a trend",
    ("k", "lower"): "k at its lower bound: the machine looks softer than the data can tell apart from the law's "
                    "evolution",
    ("k", "upper"): "k at its upper bound: the machine looks rigid (the loading right after the step is not "
                    "resolved: too few samples in it, or a misplaced step time)",
}


@attrs.frozen
class Quantity:
    """A value with its standard error and 95% interval, in the display unit."""

    value: float
    stderr: float | None
    low: float
    high: float
    unit: str
    held: bool = False  # held by the caller or the dataset (no interval: not fitted)
    bound: str = ""  # 'lower' | 'upper' where the fit ended at that bound (no interval: the bound's value)

    @property
    def digits(self) -> int:
        """Significant digits that resolve the standard error (at least 4)."""
        if not self.stderr or not self.value:
            return 4
        return max(4, min(10, math.ceil(math.log10(abs(self.value) / self.stderr)) + 2))

    @property
    def missing(self) -> str:
        """Why there is no interval: 'held', 'at its lower bound', 'at its upper bound' or 'no interval'."""
        return "held" if self.held else f"at its {self.bound} bound" if self.bound else "no interval"

    def text(self) -> str:
        unit = f" {self.unit}" if self.unit else ""
        if self.stderr is None:
            return f"{self.value:.4g}{unit} ({self.missing})"
        d = self.digits
        return f"{self.value:.{d}g} ± {self.stderr:.2g}{unit} [{self.low:.{d}g}, {self.high:.{d}g}]"


@attrs.frozen
class StepRow:
    """One dataset's velocity-step parameters in laboratory units (a, b, a - b, mu0 and mu_ss plain; Dc in um;
    k and the trend in 1/um)."""

    dataset: str
    law: str
    quantities: dict  # name -> Quantity: 'a', 'b', 'a-b', 'Dc', 'k', 'mu0', 'trend'
    phi: tuple  # (rate label, phi) per rate group, () without the AR(1) model
    steps: tuple  # ((V before, V after) [um/s]) of each step
    fits: bool | None
    goodness: str


@attrs.frozen
class StepReport:
    """What a velocity-step fit says, in the field's units: per dataset the parameter table, the sign of a - b
    against the trend, the parameters at a bound and what that means, and what the law misses."""

    rows: tuple[StepRow, ...]
    sign: tuple[str, ...] = ()
    bounds: tuple[str, ...] = ()
    missing: tuple[str, ...] = ()
    noise: tuple[str, ...] = ()

    ORDER = ("a", "b", "a-b", "Dc", "k", "mu0", "trend")

    def lines(self) -> list[str]:
        out = []
        for r in self.rows:
            steps = ", ".join(f"{v1:g} -> {v2:g} um/s" for v1, v2 in r.steps)
            out.append(f"  velocity steps of {r.dataset} ({steps}), {r.law}: value ± standard error [95% interval]")
            for name in self.ORDER:
                if name in r.quantities:
                    out.append(f"    {name:<6} = {r.quantities[name].text()}")
            if r.phi:
                out.append("    noise: AR(1), " + ", ".join(f"phi = {p:.3f} ({lab})" for lab, p in r.phi))
        out += [f"  {s}" for s in self.sign + self.bounds + self.noise + self.missing]
        return out


@attrs.frozen(eq=False)
class VelstepFit(DatasetFit):
    """A dataset's part of a velocity-step fit: its model includes the fitted trend s (x - x_ref) [s in 1/m]."""

    trend: float = 0.0
    x_ref: float = 0.0  # [m]
    x_data: np.ndarray | None = None  # the dataset's load-point displacement [m] (None: from the schedule)

    def trajectory(self, law, t=None, n: int = 401):
        tr = super().trajectory(law, t, n)
        if tr is None or not self.trend:
            return tr
        x = (np.interp(tr.t, self.target.t, self.x_data) if self.x_data is not None
             else _schedule_x(self.scene, tr.t))
        extra = self.trend * (x - self.x_ref)
        return attrs.evolve(tr, load=tr.load + extra, force=tr.force + extra * tr.N)


def _schedule_x(scene, t):
    from ...solve.quasistatic import Load

    return Load.of(scene.spring).displacement(t) * UM


def build(problem, x, rounds, *, checks=True, errors=True, n_params=None, clock=None, names=()) -> FitResult:
    """The FitResult of ``problem`` fitted at the full parameter vector x."""
    from ..fitting.predict import set_scene_quantity

    law = problem.law
    v = problem.values(x)
    free = problem.free
    n_lin = [s.B.shape[1] for s in problem.series]
    n_cols = len(free) + sum(n_lin)
    # the full prewhitened Jacobian, filled by _piece (a replicate's refit, errors=False, needs none)
    J = np.zeros((sum(s.n for s in problem.series), n_cols if errors else 0))
    pieces, col = [], len(free)
    for s, q in zip(problem.series, n_lin):
        pieces.append(_piece(problem, s, v, x, free, J, col))
        col += q
    at_bound = _at_bounds(problem, x)
    keep = [j for j in range(n_cols) if not (j < len(free) and problem.params[free[j]].name in at_bound)]
    norms = np.linalg.norm(J, axis=0) if errors else np.ones(n_cols)
    effect = norms > 1e-9 * max(float(norms.max()) if norms.size else 0.0, 1e-300)
    no_effect = [problem.params[free[j]].name for j in range(len(free)) if not effect[j]]
    keep = [j for j in keep if effect[j]]
    cov, rank = _covariance(J[:, keep] if errors else J[:, :0])
    full = np.full((n_cols, n_cols), np.nan)
    if cov is not None and errors:
        full[np.ix_(keep, keep)] = cov
    chisqr = float(sum(p["z"] @ p["z"] for p in pieces))
    n = sum(p["n"] for p in pieces)
    n_phi = sum(s.refs.size for s in problem.series if s.ar1)
    k = (rank if errors else (len(free) + sum(n_lin) if n_params is None else int(n_params)))
    kind = pieces[0]["kind"] if len({p["kind"] for p in pieces}) == 1 else "mixed"
    per, goods = [], []
    for s, p in zip(problem.series, pieces):
        g = _goodness(s, p, round(k / len(pieces)) + (s.refs.size if s.ar1 else 0), J[p["rows"], keep]
                      if errors and checks else None)
        goods.append(g)
        lawp = {"mu0": p["mu0"], "a": v["a"], "b": v["b"], "Dc": v["Dc"] * UM}
        scene = set_scene_quantity(s.target.dataset.scene, "spring.stiffness", v["k"][s.index] / UM)
        target = attrs.evolve(s.target, sigma=s.sigma.copy())
        per.append(VelstepFit(target, "ode", lawp, scene, p["model"], float(p["r"] @ p["r"]),
                              float(math.sqrt(np.mean(p["r"] ** 2))), float(p["z"] @ p["z"]), g,
                              trend=p["trend"] / UM, x_ref=s.x_ref * UM,
                              x_data=s.x * UM if "x" in s.target.dataset.columns else None))
    ll = sum(p["ll"] for p in pieces)
    k_lik = k + n_phi
    reason = LIKELIHOOD_REASON.get(kind, "")
    if n_phi:
        reason += ("; correlated noise: AR(1) per sampling rate (phi profiled, counted as a parameter), the "
                   "likelihood, tests and error bars on the prewhitened series")
    stats = Stats(n_points=n, n_params=k, n_free=len(free) + sum(n_lin), chisqr=chisqr,
                  redchi=chisqr / (n - k) if n > k else math.inf,
                  rss=per[0].rss if len(per) == 1 else math.nan, rmse=per[0].rmse if len(per) == 1 else math.nan,
                  aic=ll + 2 * k_lik, aicc=ll + 2 * k_lik + (2 * k_lik * (k_lik + 1) / (n - k_lik - 1)
                                                             if n - k_lik - 1 > 0 else math.inf),
                  bic=ll + k_lik * math.log(n), likelihood=kind, neg2loglik=ll, k_lik=k_lik, likelihood_reason=reason)
    params, correl, quantities = _params(problem, x, v, pieces, free, full, at_bound, errors)
    structure = {"at_bounds": tuple(at_bound), "sides": {name: side for name, (_, side, _) in at_bound.items()},
                 "ratios": (), "no_effect": tuple(no_effect), "k_eff": k, "n_free": len(free) + sum(n_lin)}
    ident = make_verdict(structure, params, correl)
    meanings = {name: text for name, (_, _, text) in at_bound.items()}
    meanings.update({name: NO_EFFECT.get(next(p.key for p in problem.params if p.name == name), "")
                     for name in no_effect})
    ident = attrs.evolve(ident, warnings=tuple(_with_meaning(w, meanings) for w in ident.warnings))
    notes = []
    if rounds:
        notes.append(f"AR(1) noise: the fit and the profile of phi alternated {rounds} times")
    if problem.failures:
        notes.append(f"{problem.failures} of {problem.nfev} evaluations could not be solved and were penalized "
                     f"(last: {problem.last_error})")
    report = None
    if checks and errors:
        report = _report(problem, x, v, pieces, quantities, at_bound, goods)
        notes += list(report.sign) + list(report.noise) + list(report.missing)
    clock = clock or (time.perf_counter(), time.thread_time())
    return FitResult(law=law.name, solver="ode", datasets=tuple(names), status="ok", params=params,
                     correlations=correl, stats=stats, identifiability=ident, per_dataset=tuple(per),
                     nfev=problem.nfev, wall_time=time.perf_counter() - clock[0],
                     cpu_time=time.thread_time() - clock[1], message="velocity-step fit (trust-region least squares, "
                     "variable projection)", notes=tuple(notes), goodness=combine(goods), velstep=report)


def _piece(problem, s, v, x, free, J, col: int) -> dict:
    """One dataset at the solution: model, residuals (plain and prewhitened), the linear coefficients, -2 ln L; its
    rows of the full prewhitened Jacobian J (the nonlinear columns, and its linear ones from column ``col``) are
    written into J."""
    from ...solve import quasistatic

    sol = quasistatic.solve(problem.code, v["a"], v["b"], v["Dc"], v["k"][s.index], s.load, s.t, problem.rtol,
                            sensitivities=bool(J.shape[1]))
    c = s.linear(v["a"], v["b"], sol.m)
    model = s.offset(v["a"], v["b"]) + sol.m + s.B @ c
    r = model - s.y
    z = ar1.whiten(r / s.sigma, s.phi)
    start = sum(t.n for t in problem.series[:s.index])
    rows = slice(start, start + s.n)
    if J.shape[1]:
        J[rows, :len(free)] = ar1.whiten(problem.columns(s, v, x, sol.S, free) / s.sigma[:, None], s.phi)
        J[rows, col:col + s.B.shape[1]] = ar1.whiten(s.B / s.sigma[:, None], s.phi)
    ll = float(z @ z) + float(np.sum(np.log(2 * math.pi * s.sigma ** 2))) + ar1.log_det(s.phi)
    mu_ss = (c[0] if s.mu0 is None else s.mu0 + (v["a"] - v["b"]) * s.L1)
    trend = float(c[-1]) if s.trend else 0.0
    return dict(n=s.n, model=model, r=r, z=z, c=c, rows=rows, ll=ll, mu0=float(mu_ss - (v["a"] - v["b"]) * s.L1),
                mu_ss=float(mu_ss), trend=trend, kind=s.kind)


def _covariance(A) -> tuple[np.ndarray | None, int]:
    """(inverse of A'A, or None where A's columns are dependent; rank of A)."""
    if not A.shape[1]:
        return np.zeros((0, 0)), 0
    norms = np.linalg.norm(A, axis=0)
    An = A / norms
    sv = np.linalg.svd(An, compute_uv=False)
    rank = int(np.sum(sv > 1e-10 * sv[0]))
    if rank < A.shape[1]:
        return None, rank
    cov = np.linalg.inv(An.T @ An) / np.outer(norms, norms)
    return cov, rank


def _at_bounds(problem, x) -> dict:
    """Display name -> (key, 'lower' | 'upper', what it means) for every free nonlinear parameter within AT_BOUND
    of a bound."""
    out = {}
    for i in problem.free:
        p = problem.params[i]
        lo, hi = p.bounds_x
        for side, b in (("lower", lo), ("upper", hi)):
            if math.isfinite(b) and abs(x[i] - b) <= AT_BOUND * (1.0 if p.transform == "log" else max(1.0, abs(b))):
                out[p.name] = (p.key, side, BOUND_MEANING.get((p.key, side), f"{p.name} at its {side} bound"))
    return out


#: Why a parameter of the velocity-step fit has no effect on the prediction.
NO_EFFECT = {"Dc": "b = 0, so the state does not enter the friction", "k": "no step moves the load point",
             "a": "", "b": ""}


def _with_meaning(warning: str, meanings: dict) -> str:
    """A generic identifiability warning with what it means on velocity-step data."""
    for name, text in meanings.items():
        if warning.startswith(f"{name} is at"):  # what it means here, naming the bound once
            return text if text.startswith(f"{name} at") else f"{warning.split(': ', 1)[0]}: {text}"
        if text and warning.startswith(f"{name} has no effect"):
            return f"{name} has no effect on the prediction near the best fit ({text})"
    return warning


def _goodness(s, p, k_each: int, J):
    """The goodness of fit of one dataset on its prewhitened residuals (``inference.diagnostics.goodness``)."""
    from ...io.noise import ratio_pvalue_moments

    z = p["z"]
    chi = float(z @ z)
    white = ljung_box(z, s.refs.size) if s.ar1 else math.nan  # the AR(1) model says the prewhitened z are white
    if s.kind != "estimated":
        return goodness(z, k_each, s.kind, white_p=white)
    if s.ar1:
        df = ar1.pooled_df(s.noise_ests, s.labels)
        est = s.noise_ests[0] if len(s.noise_ests) == 1 else None
    else:
        est = s.target.dataset.noise_est.get(s.target.observable)
        df = est.df if est is not None else math.inf
    chi_p = f_pvalue(chi, z.size - k_each, df)
    if J is not None and est is not None and chi_p >= SHARPEN_BELOW:
        sharp = ratio_pvalue_moments(est, chi, J)
        chi_p = chi_p if sharp is None else sharp
    return goodness(z, k_each, "estimated", df, chi_p, white_p=white)


def _params(problem, x, v, pieces, free, cov, at_bound, errors) -> tuple[dict, dict, dict]:
    """ParamResults (SI), correlations between the reported parameters and, per dataset, the Quantities in
    laboratory units."""
    multi = len(problem.series) > 1
    nf = len(free)
    n_cols = cov.shape[0]
    grads, entries = {}, []  # name -> gradient over the covariance's columns (SI value per column unit)

    known = np.isfinite(np.diag(cov)) if n_cols else np.zeros(0, dtype=bool)  # columns in the covariance

    def add(name, key, kind, value, grad, unit, vary, initial, lower, upper, datasets, fixed_by=""):
        err = None
        if errors and grad is not None and vary and name not in at_bound and np.any(known[grad != 0]):
            grad = np.where(known, grad, 0.0)  # a parameter held at its bound (or without effect) adds nothing
            var = float(grad @ np.nan_to_num(cov) @ grad)
            if var >= 0:
                err = math.sqrt(var)
        if grad is not None and err is not None:
            grads[name] = grad
        entries.append(ParamResult(name, key, kind, value, err, unit, vary, initial, lower, upper, datasets, fixed_by))

    col = {i: j for j, i in enumerate(free)}
    names_all = tuple(s.target.name for s in problem.series)
    for i, p in enumerate(problem.params):
        if p.target >= 0:
            continue
        g = np.zeros(n_cols)
        si = UM if p.key == "Dc" else 1.0
        value = p.from_x(x[i]) * si
        if i in col:
            g[col[i]] = p.slope(x[i]) * si
        add(p.name, p.key, "law", value, g if i in col else None, law_unit(problem.law, p.key), p.vary, p.value * si,
            p.lower * si, p.upper * si, names_all, p.fixed_by)
    ia, ib = (next(i for i, p in enumerate(problem.params) if p.key == key) for key in ("a", "b"))
    g_ab = np.zeros(n_cols)
    for i, sign in ((ia, 1.0), (ib, -1.0)):
        if i in col:
            g_ab[col[i]] = sign * problem.params[i].slope(x[i])
    lin_col = nf
    quantities = {}
    for s, pc in zip(problem.series, pieces):
        suffix = f"[{s.target.name}]" if multi else ""
        # mu0 (the law's, at V0) = mu_ss - (a - b) L1
        g = np.zeros(n_cols)
        if s.mu0 is None:
            g[lin_col] = 1.0
            g -= s.L1 * g_ab
        add("mu0" + suffix, "mu0", "law", pc["mu0"], g if s.mu0 is None else None, "", s.mu0 is None,
            problem.law.spec("mu0").default, problem.law.spec("mu0").lower, problem.law.spec("mu0").upper,
            (s.target.name,), "" if s.mu0 is None else "held by the caller")
        gk = np.zeros(n_cols)
        ik = next(i for i, p in enumerate(problem.params) if p.key == "k" and p.target == s.index)
        pk = problem.params[ik]
        if ik in col:
            gk[col[ik]] = v["k"][s.index] / UM
        add(pk.name, "spring.stiffness", "scene", v["k"][s.index] / UM, gk if ik in col else None, "1/m", pk.vary,
            pk.value / UM, pk.lower / UM, pk.upper / UM, (s.target.name,), pk.fixed_by)
        if s.trend:
            gt = np.zeros(n_cols)
            gt[lin_col + s.B.shape[1] - 1] = 1.0 / UM
            add("trend" + suffix, "trend", "linear", pc["trend"] / UM, gt, "1/m", True, 0.0, -math.inf, math.inf,
                (s.target.name,))
        if s.ar1:
            for g_i, phi in enumerate(s.phi_groups):
                n_g = int(np.sum(s.labels == g_i))
                label = "phi" + (f"@{1 / s.refs[g_i]:.3g}Hz" if s.refs.size > 1 else "") + suffix
                entries.append(ParamResult(label, "phi", "noise", float(phi), math.sqrt(max(1 - phi * phi, 0) / n_g),
                                           "", True, 0.0, ar1.PHI_RANGE[0], ar1.PHI_RANGE[1], (s.target.name,),
                                           "profiled"))
        lin_col += s.B.shape[1]
        quantities[s.target.name] = {}
    # a - b
    both = ia in col or ib in col
    add("a-b", "a-b", "derived", v["a"] - v["b"], g_ab if both else None, "", both, 0.0, -math.inf, math.inf,
        names_all, "derived: the combination the data determine")
    params = {p.name: p for p in entries}
    correl = {}
    names = sorted(grads)
    for x1 in range(len(names)):
        for x2 in range(x1 + 1, len(names)):
            a, b = names[x1], names[x2]
            if params[a].kind == "derived" or params[b].kind == "derived":
                continue
            ga, gb = grads[a], grads[b]
            va, vb = ga @ np.nan_to_num(cov) @ ga, gb @ np.nan_to_num(cov) @ gb
            if va > 0 and vb > 0:
                correl[(a, b)] = float(ga @ np.nan_to_num(cov) @ gb / math.sqrt(va * vb))
    for s in problem.series:
        suffix = f"[{s.target.name}]" if multi else ""
        q = quantities[s.target.name]
        kname = next(p.name for p in problem.params if p.key == "k" and p.target == s.index)
        for key, name, factor, unit in (("a", "a", 1.0, ""), ("b", "b", 1.0, ""), ("a-b", "a-b", 1.0, ""),
                                        ("Dc", "Dc", 1 / UM, "um"), ("k", kname, UM, "1/um"),
                                        ("mu0", "mu0" + suffix, 1.0, ""), ("trend", "trend" + suffix, UM, "1/um")):
            if key != "trend" or s.trend:
                q[key] = _quantity(params[name], factor, unit, log=key in ("Dc", "k"),
                                   bound=at_bound[name][1] if name in at_bound else "")
    return params, correl, quantities


def law_unit(law, key: str) -> str:
    return law.spec(key).unit


def _quantity(p: ParamResult, factor: float, unit: str, log: bool = False, bound: str = "") -> Quantity:
    """A ParamResult in a display unit (factor from SI), with its 95% interval (log-normal for Dc and k);
    ``bound``: the side of the bound the fit ended at, if any."""
    v = p.value * factor
    if not p.vary and p.kind != "derived":
        return Quantity(v, None, math.nan, math.nan, unit, held=True)
    if p.stderr is None or bound:
        return Quantity(v, None, math.nan, math.nan, unit, bound=bound)
    e = p.stderr * factor
    if log and v > 0:
        f = math.exp(1.959964 * e / v)
        return Quantity(v, e, v / f, v * f, unit)
    return Quantity(v, e, v - 1.959964 * e, v + 1.959964 * e, unit)


def _report(problem, x, v, pieces, quantities, at_bound, goods) -> StepReport:
    """The StepReport: the table, the sign of a - b against the trend, bounds, the noise and what the law misses."""
    rows, sign, noise = [], [], []
    ab = v["a"] - v["b"]
    for s, pc, g in zip(problem.series, pieces, goods):
        V = s.load.velocities
        steps = tuple((float(V[i]), float(V[i + 1])) for i in range(V.size - 1))
        phi = tuple((f"{1 / r:.3g} Hz", float(p)) for r, p in zip(s.refs, s.phi_groups)) if s.ar1 else ()
        rows.append(StepRow(s.target.name, problem.law.name, quantities[s.target.name], phi, steps, g.fits, g.text))
        if s.trend:
            sign += _sign_check(problem, x, s, pc, ab, steps)
        if s.ar1 and math.isfinite(g.lag1) and abs(g.lag1) > MISSING_Z / math.sqrt(s.n):
            noise.append(f"{s.target.name}: the noise is not AR(1): the prewhitened residuals keep a lag-1 "
                         f"autocorrelation of {g.lag1:+.2f} (beyond {MISSING_Z:g} / sqrt(n))")
    missing = _missing(problem, x, pieces, goods, v, at_bound) if at_bound or any(g.fits is False for g in goods) else []
    bounds = tuple(text for _, _, text in at_bound.values())
    return StepReport(tuple(rows), tuple(sign), bounds, tuple(missing), tuple(noise))


def _sign_check(problem, x, s, pc, ab, steps) -> list[str]:
    """Whether the sign of a - b on dataset s depends on its fitted trend (module docstring)."""
    ratios = [abs(math.log(v2 / v1)) for v1, v2 in steps if v1 > 0 and v2 > 0]
    if not ratios:
        return []
    slip = float(s.x[-1] - s.x[0])
    size = abs(pc["trend"]) * slip
    evo = abs(ab) * max(ratios)
    refit = _refit(problem, x, s, trend=False)
    without = None if refit is None else refit[0]
    flips = without is not None and math.copysign(1, without) != math.copysign(1, ab)
    if size > evo or flips:
        why = []
        if size > evo:
            why.append(f"the trend over the record's slip ({pc['trend']:.3g} /um x {slip:.4g} um = {size:.2g}) exceeds "
                       f"|a - b| ln(V2/V1) = {evo:.2g}")
        if flips:
            why.append(f"without the trend a - b = {without:+.4g}")
        return [f"{s.target.name}: the sign of a - b ({ab:+.4g}) depends on the trend: " + "; ".join(why)]
    tail = f" (without the trend a - b = {without:+.4g})" if without is not None else ""
    return [f"{s.target.name}: the sign of a - b ({ab:+.4g}) does not depend on the trend{tail}"]


def _refit(problem, x, s, trend: bool):
    """(a - b, chi-square) of a refit of the problem with dataset s's trend switched on or off (None if it fails):
    the other datasets and the noise model as they are."""
    B0, trend0, Q0, Qs0, y0, ys0 = s.B, s.trend, s.Q, s.Q_search, s.y_ref, s.y_ref_search
    try:
        s.trend = trend
        s.B = s.B[:, :-1] if not trend else np.column_stack([s.B, s.x - s.x_ref])
        s._set_projection()
        problem._cache = None
        xr, _, ok = problem.local(x, problem.free, search=True)  # on the subsample, then on every sample
        xr, cost, ok = problem.local(xr if ok else x, problem.free, max_nfev=REFIT_EVALS)
        if not ok:
            return None
        v = problem.values(xr)
        return v["a"] - v["b"], 2 * cost
    finally:
        s.B, s.trend, s.Q, s.Q_search, s.y_ref, s.y_ref_search = B0, trend0, Q0, Qs0, y0, ys0
        problem._cache = None


def _strengthening(problem, x) -> str:
    """A refit with b free to go below 0 from where the bound held b at 0: the fit, if it ends there, and the best
    grid points of the search whose a, b fit ended there (``Problem.b_held``); from anywhere else the bound did not
    act, and a local refit returns where it started. The sentence when it finds b < 0 and lowers chi-square beyond
    CHI2_1_999 ('' otherwise)."""
    ib = next(i for i, p in enumerate(problem.params) if p.key == "b")
    p = problem.params[ib]
    starts = ([x] if x[ib] <= p.bounds_x[0] + AT_BOUND else []) + problem.b_held[:2]
    if not p.vary or not starts:
        return ""
    chi_now = problem.evaluate(x, problem.free)[0]
    best = None
    try:
        problem.params[ib] = attrs.evolve(p, lower=-p.upper)
        problem._cache = None
        tried = [problem.local(x0, problem.free, search=True) for x0 in starts]
        tried = [t for t in tried if t[2]]  # on the subsample; the best one then on every sample
        if tried:
            xr, cost, ok = problem.local(min(tried, key=lambda t: t[1])[0], problem.free, max_nfev=REFIT_EVALS)
            best = (xr, cost) if ok else None
    finally:
        problem.params[ib] = p
        problem._cache = None
    if best is None:
        return ""
    xr, cost = best
    v = problem.values(xr)
    drop = chi_now - 2 * cost
    if v["b"] < 0 and drop > CHI2_1_999:
        return (f"a strengthening evolution: a refit that lets b go below 0 gives b = {v['b']:.3g} (a = {v['a']:.3g}, "
                f"Dc = {v['Dc']:.3g} um) and lowers chi-square by {drop:.4g}; the rate-and-state laws here need b >= 0")
    return ""


def _missing(problem, x, pieces, goods, v, at_bound) -> list[str]:
    """What the data show that the law misses (module docstring), from the fit's residuals and refits."""
    text = _strengthening(problem, x)
    if text:  # the first feature found; the others would be judged on a law the data reject
        return [f"{', '.join(s.target.name for s in problem.series)}: {text}"]
    out = []
    for s, pc, g in zip(problem.series, pieces, goods):
        if not s.trend:
            r = _refit(problem, x, s, trend=True)
            chi_now = float(pc["z"] @ pc["z"])
            if r is not None and chi_now - r[1] > CHI2_1_999:
                out.append(f"{s.target.name}: a trend of friction with slip (a refit with one lowers chi-square by "
                           f"{chi_now - r[1]:.4g})")
        if g.fits is False:
            out += _structure(s, pc, v)
    return out


def _structure(s, pc, v) -> list[str]:
    """Windows of slip after each step where the mean residual departs from 0 by more than MISSING_Z standard
    errors of a mean of the fitted noise (AR(1): the variance of a mean inflated by (1 + phi) / (1 - phi))."""
    out = []
    Dc = v["Dc"]
    r = pc["r"] / s.sigma
    times = list(s.load.times[1:]) + [math.inf]
    for j, ts in enumerate(times[:-1]):
        sel = (s.t >= ts) & (s.t < times[j + 1])
        if sel.sum() < 20:
            continue
        slip = s.x[sel] - float(np.interp(ts, s.t, s.x))
        top = float(slip.max())
        if not top > Dc / 10:
            continue
        edges = np.geomspace(Dc / 10, top, 9)
        flagged = []
        for lo, hi in zip(edges[:-1], edges[1:]):
            w = (slip >= lo) & (slip < hi)
            nw = int(w.sum())
            if nw < 10:
                continue
            phi = float(np.median(s.phi[sel][w])) if s.ar1 else 0.0
            se = math.sqrt((1 + phi) / (1 - phi) / nw) if phi < 1 else math.inf
            zmean = float(np.mean(r[sel][w])) / se
            if abs(zmean) > MISSING_Z:
                flagged.append((lo, hi, zmean))
        beyond = [f for f in flagged if f[0] >= 3 * Dc]
        if len(beyond) >= 2:
            span = f"{beyond[0][0]:.3g} to {beyond[-1][1]:.3g} um"
            out.append(f"{s.target.name}: a slower evolution after step {j + 1} (a second state variable): mean "
                       f"residuals beyond {MISSING_Z:g} standard errors from {span} of slip after the step, beyond "
                       f"3 Dc = {3 * Dc:.3g} um")
        elif flagged:
            span = ", ".join(f"{lo:.3g}-{hi:.3g} um ({z:+.1f} SE)" for lo, hi, z in flagged)
            out.append(f"{s.target.name}: the shape of the transient after step {j + 1}: mean residuals beyond "
                       f"{MISSING_Z:g} standard errors at slip {span}")
    return out
