"""The velocity-step fit's result: the FitResult of a fitted ``velstep.Problem``, and what it says in the field's
units (``StepReport``).

* Error bars: the full covariance of every parameter fitted jointly (nonlinear and linear), from the prewhitened
  Jacobian at the noise the likelihood uses, not rescaled (the noise is measured or estimated without the law,
  as for every fit). Where no candidate noise model whitens the residuals (an AR(1) working model, ``noise.arp``),
  the Newey-West sandwich of the scores instead, and the law-fit bands under the data's best candidate. A
  parameter at a bound gets no error bar; the others' are then those with it held there.
* Bounds: a parameter within AT_BOUND (relative) of a bound is reported at it, with what that means for these
  data (``BOUND_MEANING``).
* The sign of a - b and the trend: where a trend is fitted, the result says whether the sign of a - b depends on
  it: when |s| times the slip over the record exceeds |a - b| ln(V2/V1) at the largest step, or when a refit
  without the trend gives a - b of the other sign.
* Goodness under the data's AR(p) model (``correlation = "arp"``): two questions kept apart. Whether the noise
  model is adequate: the Ljung-Box test of the whitened residuals (reported, not a verdict on the law). Whether
  the law fits: the bands of slip after each step against the record's steady state (``noise.misfit``); "does
  not fit" rests on that test alone, with its band named. The innovation level is profiled, so chi-square is
  n by construction and is no test there.
* What the data show that the law misses, where it does not fit: ``velstep.missing``.
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
from ..diagnostics.goodness import FITS_LEVEL, SHARPEN_BELOW, WHITE_LAGS, combine, f_pvalue, goodness, law_fit, ljung_box
from . import missing as velstep_missing
from ..diagnostics.identifiability import make_verdict

from .missing import AT_BOUND, CHI2_1_999, MISSING_Z, REFIT_EVALS  # noqa: F401  (the fit's public names)
from .table import Quantity, StepReport, StepRow  # noqa: F401  (the fit's public names)

#: What a parameter at a bound means on velocity-step data: (key, 'lower' | 'upper') -> sentence.
BOUND_MEANING = {
    ("b", "lower"): "b at 0: the evolution runs the other way; a single-state law cannot follow it",
    ("b", "upper"): "b at its upper bound: the evolution effect is larger than the law allows",
    ("a", "lower"): "a at its lower bound: no direct effect is resolved (the step is not sampled fast enough)",
    ("a", "upper"): "a at its upper bound: the direct effect is larger than the law allows",
    ("Dc", "lower"): "Dc at its lower bound: the evolution is faster than the sampling resolves",
    ("Dc", "upper"): "Dc at its upper bound (the record's slip after the step): the evolution is slower than the "
                     "record is long, and cannot be told from a trend",
    ("c", "lower"): "c at 0: no stress-weakening of the state is resolved (Nagata's law is the aging law here)",
    ("c", "upper"): "c at its upper bound: the state weakens with stress more than the law allows",
    ("k", "lower"): "k at its lower bound: the machine looks softer than the data can tell apart from the law's "
                    "evolution",
    ("k", "upper"): "k at its upper bound: the machine looks rigid (the loading right after the step is not "
                    "resolved: too few samples in it, or a misplaced step time)",
}


@attrs.frozen(eq=False)
class VelstepFit(DatasetFit):
    """A dataset's part of a velocity-step fit: its model includes the fitted trend s (x - x_ref) [s in 1/m]."""

    trend: float = 0.0
    x_ref: float = 0.0  # [m]
    x_data: np.ndarray | None = None  # the dataset's load-point displacement [m] (None: from the schedule)
    loglik: np.ndarray | None = None  # each sample's log-likelihood under the fit's noise model (``vuong``)
    noise_state: dict | None = None  # the fitted noise model (``velstep.series.Series.noise_state``), for refits
    refit: dict = attrs.field(factory=dict)  # the fit's own model for a refit: {'trend': bool, 'stiffness': bool}

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
    if cov is not None and errors and any(s.arp and s.noise.robust for s in problem.series):
        cov = _sandwich(problem, J[:, keep], pieces, cov)
    full = np.full((n_cols, n_cols), np.nan)
    if cov is not None and errors:
        full[np.ix_(keep, keep)] = cov
    chisqr = float(sum(p["z"] @ p["z"] for p in pieces))
    n = sum(p["n"] for p in pieces)
    n_phi = sum(s.n_noise for s in problem.series)
    k = (rank if errors else (len(free) + sum(n_lin) if n_params is None else int(n_params)))
    kind = pieces[0]["kind"] if len({p["kind"] for p in pieces}) == 1 else "mixed"
    per, goods = [], []
    for s, p in zip(problem.series, pieces):
        g = _goodness(s, p, round(k / len(pieces)) + s.n_noise, J[p["rows"], keep] if errors and checks else None,
                      v)
        goods.append(g)
        lawp = {"mu0": p["mu0"], "a": v["a"], "b": v["b"], "Dc": v["Dc"] * UM} | {e: v[e] for e in problem.extra}
        scene = set_scene_quantity(s.target.dataset.scene, "spring.stiffness", v["k"][s.index] / UM)
        target = attrs.evolve(s.target, sigma=s.sigma.copy())
        per.append(VelstepFit(target, "ode", lawp, scene, p["model"], float(p["r"] @ p["r"]),
                              float(math.sqrt(np.mean(p["r"] ** 2))), float(p["z"] @ p["z"]), g,
                              trend=p["trend"] / UM, x_ref=s.x_ref * UM,
                              x_data=s.x * UM if "x" in s.target.dataset.columns else None, loglik=p["loglik"],
                              noise_state=s.noise_state(), refit={"trend": bool(s.trend), "stiffness": any(
                                  q.key == "k" and q.target == s.index and q.vary for q in problem.params)}))
    ll = sum(p["ll"] for p in pieces)
    k_lik = k + n_phi
    reason = LIKELIHOOD_REASON.get(kind, "")
    if any(s.arp for s in problem.series):
        reason += ("; correlated noise chosen by the data: AR(p) by BIC (ARMA(1,1) where the order runs to its cap) "
                   "per sampling rate, its innovation level profiled, alternated with the fit; coefficients and "
                   "levels counted as parameters; the likelihood, tests and error bars on the whitened series")
        reason += "".join(f"; {s.target.name} at {rate}: {what}" for s in problem.series if s.arp
                          for rate, what in s.noise.describe() if "working model" in what)
    elif n_phi:
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
        notes.append(f"AR(p) noise chosen by the data: the fit and the noise model alternated {rounds} times"
                     if any(s.arp for s in problem.series) else
                     f"AR(1) noise: the fit and the profile of phi alternated {rounds} times")
    if problem.failures:
        notes.append(f"{problem.failures} of {problem.nfev} evaluations could not be solved and were penalized "
                     f"(last: {problem.last_error})")
    report = None
    if checks and errors:
        report = velstep_missing.report(problem, x, v, pieces, quantities, at_bound, goods)
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
    sol = problem.solve(v, s, s.t, problem.rtol, bool(J.shape[1]))
    c = s.linear(v["a"], v["b"], sol.m)
    model = s.offset(v["a"], v["b"]) + sol.m + s.B @ c
    r = model - s.y
    z = s.white(r / s.sigma)
    start = sum(t.n for t in problem.series[:s.index])
    rows = slice(start, start + s.n)
    if J.shape[1]:
        J[rows, :len(free)] = s.white(problem.columns(s, v, x, sol.S, free) / s.sigma[:, None])
        J[rows, col:col + s.B.shape[1]] = s.white(s.B / s.sigma[:, None])
    terms = z * z + np.log(2 * math.pi * s.sigma ** 2) + s.log_det_terms()  # each sample's -2 ln L
    ll = float(np.sum(terms))
    mu_ss = (c[0] if s.mu0 is None else s.mu0 + (v["a"] - v["b"]) * s.L1)
    trend = float(c[-1]) if s.trend else 0.0
    return dict(n=s.n, model=model, r=r, z=z, c=c, rows=rows, ll=ll, loglik=-0.5 * terms, mu0=float(mu_ss - (v["a"] - v["b"]) * s.L1),
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


def _sandwich(problem, J, pieces, bread) -> np.ndarray:
    """The covariance where some dataset's noise no candidate model whitens (its AR(1) a working model): the
    sandwich bread (J'J)^-1 around the sum over datasets of the Newey-West long-run covariance of the scores
    J_t z_t (``noise.hac``, times n) where the working model is in use, J'J of their rows elsewhere."""
    from ..noise.hac import long_run_covariance

    meat = np.zeros_like(bread)
    for s, pc in zip(problem.series, pieces):
        Jr = J[pc["rows"]]
        if s.arp and s.noise.robust:
            meat += s.n * long_run_covariance(Jr * pc["z"][:, None], center=False)
        else:
            meat += Jr.T @ Jr
    return bread @ meat @ bread


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


def _goodness(s, p, k_each: int, J, v=None):
    """The goodness of fit of one dataset on its prewhitened residuals (``inference.diagnostics.goodness``); under
    the data's AR(p) model, the noise model's whiteness and the law's band test apart (``goodness.law_fit``)."""
    from ...io.noise import ratio_pvalue_moments

    z = p["z"]
    if s.arp:
        from ..noise.misfit import band_test

        white_p, white_text = _whiteness(s, z)
        zb = z
        if s.noise.robust:  # the law-fit test under the data's best candidate, a working model's stand-in
            zb = s.noise.whiten(p["r"] / s.sigma, best=True)
            for g in range(s.refs.size):
                sel = s.labels == g
                zb[sel] /= math.sqrt(max(float(np.mean(zb[sel] ** 2)), 1e-300)) if sel.any() else 1.0
        bands = band_test(zb, s.t, s.x, s.load.times[1:], v["Dc"], s.labels) if v is not None else None
        return law_fit(z, white_p, white_text, bands)
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


def _whiteness(s, z) -> tuple[float, str]:
    """(p, words) of the Ljung-Box test of the whitened residuals of each rate group (over max(WHITE_LAGS, p + 10)
    lags, the model's coefficients subtracted from the degrees of freedom), Bonferroni over the groups."""
    ps, parts = [], []
    for g, m in enumerate(s.noise.models):
        zg = z[s.labels == g]
        lags = max(WHITE_LAGS, m.order + 10)
        pg = ljung_box(zg, m.n_coef, lags)
        if math.isfinite(pg):
            ps.append(pg)
            parts.append(f"p = {pg:.2g} at {1 / s.refs[g]:.3g} Hz ({lags} lags)")
    if not ps:
        return math.nan, "whiteness not testable (too few samples)"
    p = min(1.0, min(ps) * len(ps))
    verdict = "whitened residuals white" if p >= FITS_LEVEL else "whitened residuals not white"
    return p, f"{verdict}: Ljung-Box " + ", ".join(parts)


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
                                        ("Dc", "Dc", 1 / UM, "um"), *((e, e, 1.0, "") for e in problem.extra),
                                        ("k", kname, UM, "1/um"),
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


