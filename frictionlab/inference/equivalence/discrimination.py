"""Can the data tell two laws apart, and are their curves equivalent within a margin? Three answers.

``analyze_equivalence(fit_a, fit_b, replicates=REPLICATES, seed=0, margin=MARGIN)`` takes the best fits of
law A and law B to one dataset (each with its own solver) and answers one of:

* **different**: the data reject one law against the other (Cox's test below, two-sided at ALPHA);
* **equivalent within delta**: an upper confidence bound of the RMS distance between the two best curves
  lies below the margin delta (in the observable's unit: ``margin``), and neither law is rejected;
* **cannot tell at this noise**: neither.

Where both laws fail their own goodness-of-fit tests neither is a valid null for the other: the pair gets
no p-value and no bound (BOTH_FAIL), only their misfits compared. The p-values of a report's tests are
adjusted together (Holm over every hypothesis of the report: ``equivalence_groups.adjust_family``); a
single call decides on its own p-values (a family of one).

1. Discrimination statistic: T = chi2_A - chi2_B on the data, at the sigma the likelihood uses (measured,
   estimated from the data without any law, or a reconstruction's stated precision: ``fitting``), so T is -2
   times the log-likelihood ratio of B against A. T > 0: B fits better. T is not pivotal: under B its
   location is c_B(theta_B), A refitted to B's noise-free curve, and the fitted theta_B moves with
   the data (area-rate's eta' at the pair's threshold noise spans 0.1-4x its true value; T and
   c_B(theta_B_hat) then correlate at 0.996), so a bootstrap of T from B's fit is centred where T
   already is and almost never rejects B. Each law is therefore tested with T centred at its own
   location, Cox's (1961) statistic with the expectation taken at the fitted values:
   S_A = T + c_A (c_A: B refitted to A's best curve) and S_B = T - c_B, each c warm-started at the
   law's own fit to the same data.
2. Null distributions (parametric bootstrap of S, Williams 1970, Godfrey 1998): replicate datasets
   are simulated from each fit (its best-fit curve plus Gaussian noise of the likelihood's sigma; draws
   from ``SeedSequence([seed, key])``, the same draws under both fits); both laws are refitted to every
   replicate, T recomputed and centred at the replicate's own refitted curve, exactly as on the data.
   With an estimated sigma each replicate's chi-squares are taken at its own estimate, sigma^2 times a
   chi-square draw of the estimate's degrees of freedom over them, so the estimate's uncertainty is in
   the p-values. Large S_A speaks against A, small S_B against B: p_A = P(S_A* >= S_A | A),
   p_B = P(S_B* <= S_B | B), each (1 + count) / (m + 1) with ties (the same curve) counted half.
3. Sequential Monte Carlo (after Besag and Clifford 1991): replicates come in batches of BATCH, up to
   ``replicates`` per null; sampling stops once the decision is clear: every p-value's 99% Clopper-
   Pearson interval lies above ALPHA / 2 (clear cases cost a batch or two), or one lies below it, or,
   from FAR_MIN replicates on, a law's observed S lies beyond all of its replicates and an exponential
   tail fitted to them (peaks over their TAIL_Q quantile u: p = (1 - TAIL_Q) exp(-(S - u) / b), b the
   mean excess at its TAIL_CONF upper confidence bound) puts its p below FAR_P. Under normal,
   chi-square (1 and 3 dof), Gumbel and exponential nulls the estimate is conservative: P(p <= v) <= v
   at v = FAR_P, 1e-3 and 1e-4 (tests/test_equivalence_shortcut.py). That tail estimate (at least TAIL_FLOOR: beyond it, extrapolation)
   is then the law's p, below the Monte-Carlo floor 1 / (m + 1) that a Holm step would
   otherwise sit on. The Monte-Carlo standard error sqrt(p (1 - p) / m) of each p is reported, and how
   many replicates were drawn.
4. Different: p = min(1, 2 min(p_A, p_B)) (Bonferroni over the two one-sided nulls) below ALPHA, after the
   family's adjustment; the text says which law is rejected (both, when the other's own p is below
   ALPHA / 2 too), and a law that fails its own fit tests is never called consistent with the data.
5. Equivalent within delta (an interval inclusion test in the sense of Schuirmann's two one-sided tests,
   1987; the distance is not negative, so only its upper side tests anything): the distance D = RMS of the
   two best curves' difference (``replicates.distance``: the observable's unit, or stated precisions), in
   margins X = D / delta (delta re-estimated on each replicate when it is a multiple of an estimated sigma).
   Under each law's fit L the distance the two laws' curves truly have is X_L = (L's curve against the
   other law refitted to it) / delta, and each replicate's error is e* = X* - X_L. The bound under L is
   U_L = X - mean(e*) + t(1 - ALPHA, m - 1) sd(e*) sqrt(1 + 1/m) (the t quantile and the sqrt(1 + 1/m)
   carry the Monte-Carlo error of mean and sd from m replicates), its p-value
   p_L = P(t(m - 1) >= (1 - X + mean(e*)) / (sd(e*) sqrt(1 + 1/m))). The larger of the two laws' bounds
   and p-values is the test's (either law may be the truth): equivalent within delta when that p is below
   ALPHA after the family's adjustment, i.e. when the upper bound of D lies below delta.
   benchmarks/calibration.py measures how often this is said when the curves differ by delta or more.

Noise threshold, both directions: law A refitted to B's noise-free best curve leaves D_AB (at the sigma
used); with every sigma scaled by s the refit does not move and D scales as 1 / s^2, so at
s_AB = sqrt(D_AB / CRITICAL) a fit of A to B's curve misses it by chi-square CRITICAL (3.84): data from B
at that noise reject A about half the time. Likewise s_BA. Group answers and the family's adjustment are in
``equivalence_groups``.
"""
from __future__ import annotations

from concurrent.futures import Executor

import math

import numpy as np

from ...core.blas import one_blas_thread
from ...core.errors import FrictionLabError, ParameterError
from .decomposition import decomposition
from .result import (  # noqa: F401  (the test's public names, defined with its result)
    ALONE, ALPHA, AREA_RATE, BATCH, BOTH_FAIL, CANNOT, CI_LEVEL, COULOMB, COUETTE, CRITICAL, DIFFERENT, FAR_MIN,
    FAR_P, MIN_MARGIN, MIN_REPLICATES, PAIRS, REPLICATES, TAIL_CONF, TAIL_FLOOR, TAIL_Q, TIE_REL, VERDICTS, WEAR,
    WITHIN, EquivalenceResult, _num, _p, decide, one_family_result, sentence, sentences)
from ..fitting.fit import FitResult
from .margin import MARGIN, Margin, parse_margin
from .qualitative import qualitative
from ..resampling.replicates import (ROW, centring_fit, cross_chi2, distance, noise_of, one_family, profiled,
                                     refit_options, replicate_chunk, t_stat)
from ...core.fpstate import with_own_errstate


# --- the test -------------------------------------------------------------------------------------
@with_own_errstate
@one_blas_thread
def analyze_equivalence(fit_a: FitResult, fit_b: FitResult, replicates: int = REPLICATES, seed: int = 0,
                        executor: Executor | None = None, chunk: int | None = None,
                        timeout: float | None = None, margin: float | str = MARGIN) -> EquivalenceResult:
    """Test one fitted law against another on their common dataset: different, equivalent within a
    margin, or cannot tell at this noise (the module docstring says how).

    The verdict is the test's own (a family of one); `compare` adjusts a report's tests together.

    Parameters
    ----------
    fit_a, fit_b : FitResult
        The two laws' fits to one dataset.
    replicates : int
        The most replicate datasets per null (sequential sampling stops earlier once the decision is clear).
    seed : int, default 0
        The draws depend on it, the dataset and the pair only.
    executor : concurrent.futures.Executor, optional
        Anything with ``submit`` (a process pool, a Dask client) to run the replicate refits on.
    chunk : int, optional
        Replicates per task within a batch.
    timeout : float, optional
        Time budget of each refit [s]; past it the refit counts as failed.
    margin : float or str, default 1
        The margin delta: a multiple of the noise sigma, or a quantity in the observable's unit
        (``"150 rpm"``).

    Returns
    -------
    EquivalenceResult
        The verdict with its p-values, distance, bound and margin.

    Raises
    ------
    FrictionLabError
        The two fits are not of one and the same dataset.
    ParameterError
        Fewer replicates than ``MIN_REPLICATES``, or a margin that does not read.
    """
    base = dict(dataset=fit_a.datasets[0], law_a=fit_a.law, law_b=fit_b.law, solver_a=fit_a.solver,
                solver_b=fit_b.solver, replicates=int(replicates), seed=int(seed))
    if fit_a.datasets != fit_b.datasets or len(fit_a.datasets) != 1:
        raise FrictionLabError(f"equivalence: the two fits must be of one and the same dataset "
                               f"({', '.join(fit_a.datasets)} / {', '.join(fit_b.datasets)})")
    margin = parse_margin(margin)
    if not (fit_a.ok and fit_b.ok):
        bad = fit_a if not fit_a.ok else fit_b
        return EquivalenceResult(**base, status="skipped", reason=f"{bad.law} [{bad.solver}] {bad.status}: {bad.reason}")
    if replicates < MIN_REPLICATES:
        raise ParameterError(f"equivalence: replicates must be at least {MIN_REPLICATES} (so that a p-value can fall "
                             f"below {ALPHA / 2:g}), got {replicates}")
    if fit_a.stats.likelihood not in ("known", "estimated", "stated"):
        return EquivalenceResult(**base, status="skipped",
                                 reason=f"no likelihood to test with ({fit_a.stats.likelihood_reason})")
    common = _common(fit_a, fit_b, timeout, margin)
    d_ab, d_ba = cross_chi2(fit_a, fit_b, timeout), cross_chi2(fit_b, fit_a, timeout)
    t_obs = t_stat(fit_a, fit_b)
    if common["fits"].get(fit_a.law) is False and common["fits"].get(fit_b.law) is False:
        e = EquivalenceResult(**base, **common, status="ok", t_obs=t_obs, d_ab=d_ab, d_ba=d_ba,
                              stopped="no replicates: both laws fail their fit tests")
        return decide(e)
    tol = TIE_REL * max(common["n_points"], fit_a.stats.chisqr, fit_b.stats.chisqr)
    (c_a, x_null_a), (c_b, x_null_b) = _centrings(fit_a, fit_b, timeout, common["margin"])
    if not (math.isfinite(c_a) and math.isfinite(c_b)):
        return EquivalenceResult(**base, **common, status="failed", t_obs=t_obs, d_ab=d_ab, d_ba=d_ba,
                                 reason="a law's refit to the other's best curve failed: T cannot be centred")
    obs = (t_obs + c_a, t_obs - c_b)
    rows, failed, stopped, drawn = _sample(fit_a, fit_b, replicates, seed, obs, tol, executor, chunk, timeout)
    t_a, s_a, x_a = rows["a"]
    t_b, s_b, x_b = rows["b"]
    if not common["margin_relative"]:  # a margin given as a quantity does not move with the replicate's sigma
        x_a, x_b = rows["a_abs"], rows["b_abs"]
    x_a, x_b = x_a / common["margin"], x_b / common["margin"]
    res = dict(**base, **common, t_obs=t_obs, t_a=t_a, t_b=t_b, c_a=c_a, c_b=c_b, s_a=s_a, s_b=s_b, failed=failed,
               d_ab=d_ab, d_ba=d_ba, stopped=stopped, x_a=x_a, x_b=x_b, x_null_a=x_null_a, x_null_b=x_null_b)
    if min(s_a.size, s_b.size) < MIN_REPLICATES // 2:
        return EquivalenceResult(**res, status="failed",
                                 reason=f"{failed} of {2 * drawn} replicate refits failed: too few left to test")
    p_a, p_b = _p_side(s_a, obs[0], tol), _p_side(-s_b, -obs[1], tol)
    crit_a, crit_b = float(np.quantile(t_a, 1 - ALPHA / 2)), float(np.quantile(t_b, ALPHA / 2))
    upper, p_within = within_bound(common["rms"] / common["margin"], (x_a, x_null_a), (x_b, x_null_b))
    p = min(1.0, 2 * min(p_a, p_b))
    res.update(p_a=p_a, p_b=p_b, p=p, q_a=_p_upper(-s_a, -obs[0], tol), q_b=_p_upper(s_b, obs[1], tol),
               power_a=float(np.mean(t_b > crit_a + tol)), power_b=float(np.mean(t_a < crit_b - tol)),
               upper=upper * common["margin"], p_within=p_within, p_adjusted=p, p_within_adjusted=p_within)
    return decide(EquivalenceResult(**res, status="ok"))


def within_bound(x: float, *nulls) -> tuple[float, float]:
    """(upper (1 - ALPHA) bound of the distance in margins, p-value of 'the distance is a margin or more') from
    the distance ``x`` on the data and, per null, (its replicates' distances, the distance under that null):
    the larger bound and p over the nulls (module docstring, 5)."""
    from scipy.stats import t as student

    bounds, ps = [], []
    for sample, truth in nulls:
        sample = sample[np.isfinite(sample)]
        m = sample.size
        if m < 2 or not math.isfinite(truth):
            return math.inf, 1.0
        err = sample - truth
        centre, spread = x - float(np.mean(err)), float(np.std(err, ddof=1)) * math.sqrt(1 + 1 / m)
        bounds.append(centre + float(student.ppf(1 - ALPHA, m - 1)) * spread)
        if spread > 0:
            ps.append(float(student.sf((1.0 - centre) / spread, m - 1)))
        else:  # the same curve on every replicate: the bound is the distance itself
            ps.append(0.0 if centre < 1.0 else 1.0)
    return max(bounds), max(ps)


def _common(fit_a: FitResult, fit_b: FitResult, timeout: float | None, margin: Margin) -> dict:
    """The fields of a result that describe the data, the two fits and the margin (the qualitative comparison,
    which simulates both fitted laws, within the time budget of a refit)."""
    da, db = fit_a.per_dataset[0], fit_b.per_dataset[0]
    target = da.target
    sig = np.asarray(target.sigma, dtype=float)
    delta, delta_text = margin.resolve(target, fit_a.datasets[0])
    return dict(n_points=int(target.y.size), observable=target.observable, sigma=float(np.max(sig)),
                sigma_varies=bool(np.ptp(sig) > 1e-12 * np.max(sig)) and target.observable != "stated",
                noise=fit_a.stats.likelihood, rms=distance(target, da.model, db.model),
                fitted={f.law: {k: p.value for k, p in f.params.items() if p.kind == "law"} for f in (fit_a, fit_b)},
                decomposition=decomposition(fit_a) or decomposition(fit_b),
                fits={f.law: (f.goodness.fits if f.goodness is not None else None) for f in (fit_a, fit_b)},
                goodness={f.law: (f.goodness.reason if f.goodness is not None else "") for f in (fit_a, fit_b)},
                qualitative=_qualitative_within(fit_a, fit_b, timeout),
                chi2=({f.law: f.stats.neg2loglik for f in (fit_a, fit_b)} if profiled(fit_a, fit_b)
                      else {fit_a.law: fit_a.stats.chisqr, fit_b.law: fit_b.stats.chisqr}),
                statistic="−2 ln L" if profiled(fit_a, fit_b) else "χ²", closer=_closer(fit_a, fit_b),
                k={fit_a.law: fit_a.stats.n_params, fit_b.law: fit_b.stats.n_params},
                margin=delta, margin_text=delta_text,
                margin_relative=margin.relative and target.observable != "stated",
                margin_sigmas=delta if target.observable == "stated" else delta / float(np.sqrt(np.mean(sig * sig))))


def _closer(fit_a: FitResult, fit_b: FitResult) -> str:
    """Vuong's test in words where both fits have pointwise log-likelihoods of their own noise model, else ''."""
    from ..verdicts.vuong import vuong

    if getattr(fit_a.per_dataset[0], "loglik", None) is None:
        return ""
    r = vuong(fit_a, fit_b)
    return r.text if r is not None else ""


def _qualitative_within(fit_a, fit_b, timeout: float | None) -> dict:
    """``qualitative`` within ``timeout`` seconds (None: no limit); past it, 'not applicable'."""
    from ...core.workers import beat
    from ..fitting.alarm import FitTimeout, alarm

    beat()  # in a child of inference.fitting.guard: the simulations have the budget of one refit
    try:
        with alarm(timeout):
            return qualitative(fit_a, fit_b)
    except FitTimeout:
        return {"verdict": "not applicable", "differs": "", "data_differs": {}, "features": {}, "dt": float("nan"),
                "peak_time": {}}


def _centrings(fit_a, fit_b, timeout, delta: float) -> tuple[tuple[float, float], tuple[float, float]]:
    """((B refitted to A's best curve: chi-square, A's curve's distance from it / delta), (A refitted to B's
    curve: likewise)), each refit warm-started at its own fit to the data, as on every replicate (0 for one
    model)."""
    if one_family(fit_a, fit_b):
        return (0.0, 0.0), (0.0, 0.0)
    da, db = fit_a.per_dataset[0], fit_b.per_dataset[0]
    opts_a, opts_b = (refit_options(f) | {"timeout": timeout} for f in (fit_a, fit_b))
    out = []
    for law, opts, curve, noise in ((fit_b.law, opts_b, da.model, noise_of(fit_a)),
                                    (fit_a.law, opts_a, db.model, noise_of(fit_b))):
        chi, model = centring_fit(law, opts, None, da.target, curve, noise)
        out.append((chi, distance(da.target, curve, model) / delta if model is not None else math.nan))
    return out[0], out[1]


def _sample(fit_a, fit_b, most, seed, obs, tol, executor, chunk, timeout):
    """Replicates under A's fit and under B's, in batches until the decision is clear (module docstring, 3).
    Returns ({'a': (T, S_A, D / sigma-ratio), 'b': (T, S_B, D / sigma-ratio), 'a_abs': D, 'b_abs': D}, failed
    refits, why sampling stopped, replicates drawn per null); failed replicates dropped. D / sigma-ratio is
    the distance in units of the replicate's own noise estimate over the data's (the distance itself for a
    measured sigma)."""
    if one_family(fit_a, fit_b):  # one model: both refits of every replicate are the same fit, T* = 0, D* = 0
        zeros = np.zeros(MIN_REPLICATES)
        rows = {"a": (zeros, zeros.copy(), zeros.copy()), "b": (zeros.copy(), zeros.copy(), zeros.copy()),
                "a_abs": zeros.copy(), "b_abs": zeros.copy()}
        return rows, 0, "one model: T* = 0 on every replicate", MIN_REPLICATES
    from ..resampling.replicates import seed_sequence

    da, db = fit_a.per_dataset[0], fit_b.per_dataset[0]
    opts_a, opts_b = (refit_options(f) | {"timeout": timeout} for f in (fit_a, fit_b))
    est = (da.target.dataset.noise_est.get(da.target.observable) if fit_a.stats.likelihood == "estimated"
           and getattr(da.target.dataset, "noise_correlation", "none") == "none" else None)  # AR(1): each refit
    # estimates its own sigma from its replicate, so no draw of sigma is added
    args = (fit_a.law, opts_a, fit_b.law, opts_b, da.target, da.model, db.model)
    df = float(est.df) if est is not None else math.inf
    ss = seed_sequence(seed, f"{fit_a.datasets[0]}|{fit_a.law}[{fit_a.solver}]|{fit_b.law}[{fit_b.solver}]")
    found, why = [], f"the most replicates ({most} per null) drawn"
    col = {name: i for i, name in enumerate(ROW)}
    while len(found) < most:
        batch = ss.spawn(min(BATCH, most - len(found)))
        if executor is None:
            found += replicate_chunk(*args, batch, df=df)
        else:
            size = max(1, int(chunk or math.ceil(len(batch) / 4)))
            futures = [executor.submit(replicate_chunk, *args, batch[i:i + size], df=df)
                       for i in range(0, len(batch), size)]
            found += [r for fut in futures for r in fut.result()]
        arr = np.array(found, dtype=float).reshape(-1, len(ROW))
        ok_a = np.isfinite(arr[:, [col["t_a"], col["s_a"], col["d_a"]]]).all(axis=1)
        ok_b = np.isfinite(arr[:, [col["t_b"], col["s_b"], col["d_b"]]]).all(axis=1)
        ratio = arr[:, col["sigma_ratio"]]
        rows = {"a": (arr[ok_a, col["t_a"]], arr[ok_a, col["s_a"]], arr[ok_a, col["d_a"]] / ratio[ok_a]),
                "b": (arr[ok_b, col["t_b"]], arr[ok_b, col["s_b"]], arr[ok_b, col["d_b"]] / ratio[ok_b]),
                "a_abs": arr[ok_a, col["d_a"]], "b_abs": arr[ok_b, col["d_b"]]}
        done = _clear(rows["a"][1], obs[0], -rows["b"][1], -obs[1], tol)
        if done:
            why = f"{done} after {len(found)} replicates per null"
            break
    failed = int(np.sum(~ok_a) + np.sum(~ok_b))
    return rows, failed, why, len(found)


def _clear(u_a: np.ndarray, x_a: float, u_b: np.ndarray, x_b: float, tol: float) -> str:
    """Why the decision is clear from the replicates so far ('' if it is not): each law's p is the upper tail
    of its observed statistic x among its replicates u (S_A for A; -S_B for B)."""
    if min(u_a.size, u_b.size) < BATCH // 2:
        return ""
    bounds = [_cp(_count(u_a, x_a, tol), u_a.size), _cp(_count(u_b, x_b, tol), u_b.size)]
    if all(lo > ALPHA / 2 for lo, _ in bounds):
        return f"every p-value's {CI_LEVEL:.0%} Monte-Carlo interval above {ALPHA / 2:g}"
    if any(hi < ALPHA / 2 for _, hi in bounds):
        return f"a p-value's {CI_LEVEL:.0%} Monte-Carlo interval below {ALPHA / 2:g}"
    if _far(u_a, x_a) or _far(u_b, x_b):
        return f"the data lie beyond every replicate of one law, with a tail-estimated p below {FAR_P:g}"
    return ""


def _tail(sample: np.ndarray, x: float) -> float:
    """Exponential-tail estimate of P(S* >= x) from the replicates above their TAIL_Q quantile u, with the
    mean excess at its one-sided TAIL_CONF upper confidence bound (2 k mean / chi2_2k quantile, k excesses;
    the plain mean makes the estimate 2-15 times too small in a fifth of cases for chi-square-like nulls,
    tests/test_equivalence_shortcut.py). nan if no excess."""
    from scipy.stats import chi2

    u = float(np.quantile(sample, TAIL_Q))
    excess = sample[sample > u] - u
    if not excess.size or not excess.mean() > 0:
        return math.nan
    scale = float(excess.mean()) * 2 * excess.size / float(chi2.ppf(1 - TAIL_CONF, 2 * excess.size))
    return (1 - TAIL_Q) * math.exp(-(x - u) / scale)


def _far(sample: np.ndarray, x: float) -> bool:
    """Whether x lies above every value of sample (of at least FAR_MIN) with a tail-estimated p below FAR_P."""
    return sample.size >= FAR_MIN and x > float(sample.max()) and _tail(sample, x) < FAR_P


def _p_side(sample: np.ndarray, x: float, tol: float) -> float:
    """The upper-tail p of x: Monte-Carlo, or below its floor the tail estimate where x is far beyond (_far)."""
    p = _p_upper(sample, x, tol)
    return min(p, max(_tail(sample, x), TAIL_FLOOR)) if _far(sample, x) else p


def _count(sample: np.ndarray, x: float, tol: float) -> float:
    return float(np.sum(sample > x + tol)) + 0.5 * float(np.sum(np.abs(sample - x) <= tol))


def _cp(k: float, m: int) -> tuple[float, float]:
    """Clopper-Pearson CI_LEVEL interval of a proportion k / m (k may be a half count: rounded up/down)."""
    from scipy.special import betaincinv

    a = (1 - CI_LEVEL) / 2
    lo_k, hi_k = math.floor(k), math.ceil(k)
    lo = 0.0 if lo_k == 0 else float(betaincinv(lo_k, m - lo_k + 1, a))
    hi = 1.0 if hi_k >= m else float(betaincinv(hi_k + 1, m - hi_k, 1 - a))
    return lo, hi


def _p_upper(sample: np.ndarray, x: float, tol: float) -> float:
    """(1 + #{sample > x} + #{ties} / 2) / (m + 1): the bootstrap p-value of x in the upper tail."""
    return (1.0 + _count(sample, x, tol)) / (sample.size + 1.0)

