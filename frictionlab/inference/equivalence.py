"""Can the data tell two laws apart? A Cox-type discrimination test with a parametric bootstrap.

``analyze_equivalence(fit_a, fit_b, replicates=40, seed=0)`` takes the best fits of law A and law
B to one dataset (each with its own solver) and asks whether the data can tell them apart:

1. Statistic: T = chi2_A - chi2_B on the data (noise-weighted by the dataset's declared sigma, so
   with known noise T is -2 times the log-likelihood ratio of B against A; with an assumed sigma it
   is a weighted difference of residual sums, calibrated by the same bootstrap). T > 0: B fits
   better. T compares the two laws only: whether either fits is the goodness-of-fit test's question.
2. Null distributions: R replicate datasets are simulated from each fit (its best-fit curve plus
   Gaussian noise of the declared sigma; replicate r draws from ``SeedSequence([seed, key]).spawn``,
   the same draws under both fits); both laws are refitted to every replicate (warm-started at
   their best fits, closed forms where the law has one) and T recomputed. Large T speaks against
   A, small T against B: p_A = P(T* >= T | A), p_B = P(T* <= T | B), each (1 + count) / (R + 1)
   with ties (|dT| within TIE_REL of the chi-square scale: the same curve) counted half; their
   Monte-Carlo standard error sqrt(p (1 - p) / R) is reported. The other tails are reported too
   (q_A = P(T* <= T | A), q_B = P(T* >= T | B)): T beyond the favoured law's own replicates on its
   favourable side means the data are not like that law's either (neither law produces them).
3. Overlap of the two nulls: the power of the test at level ALPHA, i.e. how often data from B
   reject A (T* under B beyond the (1 - ALPHA) quantile under A) and vice versa.

Verdict: **not equivalent** when T rejects one law at ALPHA (or both: the text says which);
**equivalent** when T is consistent with both and the nulls overlap (both powers below POWER):
data of this noise cannot tell the two apart; **cannot tell at this noise** when T is consistent
with both although the test has power (T falls where the tails of the two nulls overlap).

Noise threshold: each law refitted to the other's noise-free best curve gives the cross-fit
chi-square D_AB (A to B's curve) and D_BA at the declared noise. With every sigma scaled by s the
refit does not move and D scales as 1 / s^2, so the expected Delta-chi2 max(D_AB, D_BA) equals
the critical value CRITICAL (chi-square, one degree of freedom, 95%) at
s* = sqrt(max(D) / CRITICAL): the laws differ by more than the noise when sigma < s* x the
declared sigma. (To first order E[T | B] = D_AB + k_B - k_A: a test checks the bootstrap
against this at sigma = s* sigma.)

The paper's decomposition of the wear law, lambda A u = lambda u0 (1 - b) A + (lambda u0 b /
(phi A0)) A dA/dt, rests on the truncated slip u ~ u0 (1 - b + b cos phi t) (eq 7); it is computed
for the series fit only, never for the exact solution, whose slip is u0 exp(-b (1 - cos phi t)).
The paper prints the second factor as phi/A0; dimensionally it is 1 / (phi A0). Projected by
least squares onto mu N + mu eta' dA/dt it gives the mu and eta' the claim implies.
"""
from __future__ import annotations

import math
import zlib

import attrs
import numpy as np

from ..core.display import unit
from ..core.errors import FrictionLabError, ParameterError
from ..physics.law import AreaSlipForm
from ..physics.registry import get_law
from ..physics.scene import HalfSineArea
from .fitting import FitResult, Target, fit

WEAR, AREA_RATE, COUETTE, COULOMB = "wear", "area-rate", "couette", "coulomb"
#: The pairs ``compare`` tests by default: the paper's claim, the structural identity, and the simplest law against the paper's.
PAIRS = ((WEAR, AREA_RATE), (WEAR, COUETTE), (COULOMB, WEAR))
ALPHA = 0.05  # level of the test, each side
POWER = 0.5  # the nulls overlap when data from either law reject the other less often than this
CRITICAL = 3.84  # expected Delta-chi2 at which two laws differ by more than the noise (chi2, 1 dof, 95%)
REPLICATES = 40  # default R per null
MIN_REPLICATES = 20  # the smallest p-value is 1 / (R + 1): below ALPHA only from R = 20
TIE_REL = 1e-4  # |T* - T| below this fraction of max(n, chi2) is a tie (the optimizer's resolution)
VERDICTS = ("equivalent", "not equivalent", "cannot tell at this noise")


@attrs.frozen
class Decomposition:
    """The paper's two-term form of lambda A u (series fit only), and its projection onto mu N + mu eta' dA/dt."""

    b: float
    u0: float  # [m/s]
    c_area: float  # lambda u0 (1 - b) [N/m^2]
    c_area_rate: float  # lambda u0 b / (phi A0) [N s/m^4]
    mu: float  # implied mu [-]
    eta_prime: float  # implied eta' [N s/m^2]
    r2: float  # share of the decomposition force the projection reproduces

    def as_dict(self) -> dict:
        return attrs.asdict(self)


@attrs.frozen(eq=False)
class EquivalenceResult:
    """The discrimination test of law A against law B on one dataset. SI units; chi-square values
    are in the dataset's declared noise."""

    dataset: str
    law_a: str
    law_b: str
    solver_a: str
    solver_b: str
    status: str  # ok | skipped | failed
    verdict: str = ""  # one of VERDICTS when status is ok
    explanation: str = ""
    reason: str = ""
    replicates: int = 0  # R per null
    seed: int = 0
    n_points: int = 0
    chi2: dict = attrs.field(factory=dict)  # law -> chi2 on the data
    k: dict = attrs.field(factory=dict)  # law -> identifiable parameters
    t_obs: float = math.nan  # chi2_A - chi2_B on the data
    t_a: np.ndarray = attrs.field(factory=lambda: np.zeros(0))  # T on replicates of A's fit (failed refits dropped)
    t_b: np.ndarray = attrs.field(factory=lambda: np.zeros(0))  # T on replicates of B's fit
    p_a: float = math.nan  # P(T* >= T | A): small rejects A
    p_b: float = math.nan  # P(T* <= T | B): small rejects B
    q_a: float = math.nan  # P(T* <= T | A): small means T lies beyond A's replicates on A's favourable side
    q_b: float = math.nan  # P(T* >= T | B): likewise for B
    power_a: float = math.nan  # share of B's replicates that reject A at ALPHA
    power_b: float = math.nan  # share of A's replicates that reject B at ALPHA
    failed: int = 0  # replicates dropped because a refit failed
    d_ab: float = math.nan  # A refitted to B's best curve: chi2 at the declared noise
    d_ba: float = math.nan  # B refitted to A's best curve
    sigma: float = math.nan  # declared noise of the observable (SI; the largest if it varies)
    sigma_varies: bool = False
    observable: str = ""
    threshold: float = math.nan  # sigma below which the laws differ by more than the noise (SI); 0: never
    fitted: dict = attrs.field(factory=dict)  # law -> {param: SI value}
    decomposition: Decomposition | None = None  # the paper's decomposition (wear [series] only)

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @property
    def label(self) -> str:
        return f"{self.law_a} [{self.solver_a}] vs {self.law_b} [{self.solver_b}]"

    @property
    def involves_series(self) -> bool:
        return "series" in (self.solver_a, self.solver_b)

    def mc_error(self, p: float) -> float:
        """Monte-Carlo standard error of a p-value from R replicates."""
        m = min(self.t_a.size, self.t_b.size) or 1
        return math.sqrt(max(p * (1 - p), 0.0) / m) if math.isfinite(p) else math.nan

    def threshold_text(self) -> str:
        """'wear [exact] and area-rate [exact] differ by more than the noise when sigma < 1,200 rpm (declared: 200 rpm)'."""
        if not math.isfinite(self.threshold):
            return ""
        name, f = unit(self.observable)
        both = f"{self.law_a} [{self.solver_a}] and {self.law_b} [{self.solver_b}]"
        if self.threshold == 0.0:
            return f"{both} give the same curve: indistinguishable at any noise"
        scale = "the largest declared " if self.sigma_varies else ""
        return (f"{both} differ by more than the noise when sigma < {_num(self.threshold * f)} {name} "
                f"({scale}sigma here: {_num(self.sigma * f)} {name})")

    def as_dict(self) -> dict:
        d = {k: v for k, v in attrs.asdict(self, recurse=False).items() if k != "decomposition"}
        d["t_a"], d["t_b"] = self.t_a.tolist(), self.t_b.tolist()
        d["p_a_mc_error"], d["p_b_mc_error"] = self.mc_error(self.p_a), self.mc_error(self.p_b)
        d["alpha"], d["power_level"], d["critical_dchi2"] = ALPHA, POWER, CRITICAL
        d["threshold_text"] = self.threshold_text()
        d["decomposition"] = self.decomposition.as_dict() if self.decomposition else None
        return d


def _num2(x: float) -> str:
    """Two significant figures (whole numbers from 100 on): 1.8, 0.27, 150, 1,200."""
    return f"{float(f'{x:.2g}'):,.0f}" if abs(x) >= 100 else f"{x:.2g}"


def _num(x: float) -> str:
    return f"{x:,.0f}" if abs(x) >= 100 else f"{x:.3g}"


# --- the paper's decomposition (series fit only) --------------------------------------------------
def decomposition(fw: FitResult) -> Decomposition | None:
    """The paper's decomposition of a wear-family fit solved by the series, projected onto
    mu N + mu eta' dA/dt; None for any other solver (the decomposition rests on the truncated slip)
    or a scene without the half-sine area and a normal-force model."""
    if fw.solver != "series" or not fw.ok:
        return None
    law = get_law(fw.law)
    d = fw.per_dataset[0]
    s = d.scene
    form = law.form(d.params)
    if not isinstance(form, AreaSlipForm) or not isinstance(s.area, HalfSineArea) or s.normal is None:
        return None
    A0, tc = s.area.peak, s.area.contact_time
    phi = math.pi / tc
    b = form.k * A0 / (s.mass * phi)
    c1 = form.k * s.u0 * (1 - b)
    c2 = form.k * s.u0 * b / (phi * A0)
    t = np.linspace(0.0, tc, 2001)
    A, dA = s.area(t)
    N = s.normal(t, A)
    F = c1 * A + c2 * A * dA
    basis = np.column_stack([N, dA])
    (a, c), *_ = np.linalg.lstsq(basis, F, rcond=None)
    r2 = 1.0 - float(np.sum((F - basis @ [a, c]) ** 2) / np.sum((F - F.mean()) ** 2))
    return Decomposition(b, s.u0, c1, c2, float(a), float(c / a) if a else math.nan, r2)


# --- refits ---------------------------------------------------------------------------------------
def _refit_options(f: FitResult) -> dict:
    """fit() keywords that repeat ``f``'s setup, warm-started at its best values. Of a pair that enters
    only through its ratio (eta/h) the second is held: the chi-square is the same, the search shorter."""
    held = {pair[1] for pair in (f.identifiability.ratio_only if f.identifiability else ())}
    initial = {p.key: p.value for p in f.params.values() if p.kind == "law" and p.vary and p.name not in held}
    fixed = {p.key: p.value for p in f.params.values()
             if p.kind == "law" and (p.fixed_by == "held by the caller" or (p.vary and p.name in held))}
    free = {p.key: (p.lower, p.upper, p.value) for p in f.params.values() if p.kind == "scene" and p.vary}
    return {"solver": f.per_dataset[0].solver, "initial": initial, "fixed": fixed, "free": free}


def _refit(law: str, opts: dict, target: Target, scan: int = 0, n_starts: int = 1) -> FitResult:
    return fit(law, target, solver=opts["solver"], initial=opts["initial"], fixed=opts["fixed"] or None,
               free=opts["free"] or None, scan=scan, n_starts=n_starts, checks=False, errors=False,
               timeout=opts.get("timeout"))


def _with_y(target: Target, y: np.ndarray, what: str) -> Target:
    return Target(target.dataset, target.observable, y, target.sigma, what)


def cross_chi2(own: FitResult, other: FitResult, timeout: float | None = None) -> float:
    """``own``'s law refitted to ``other``'s noise-free best curve: the chi-square it is left with
    at the declared noise (nan if the refit fails, or takes longer than ``timeout`` seconds)."""
    d = other.per_dataset[0]
    tg = _with_y(d.target, d.model.copy(), f"best fit of {other.law}")
    r = _refit(own.law, _refit_options(own) | {"timeout": timeout}, tg, scan=25, n_starts=2)
    return float(r.stats.chisqr) if r.ok else math.nan


def _replicate_chunk(law_a, opts_a, law_b, opts_b, target, model_a, model_b, seeds) -> list[tuple[float, float]]:
    """(T under A, T under B) per seed; nan where a refit failed. Runs in a worker."""
    out = []
    for ss in seeds:
        eps = np.random.default_rng(ss).standard_normal(target.y.size) * target.sigma
        row = []
        for model in (model_a, model_b):
            tg = _with_y(target, model + eps, "parametric bootstrap replicate")
            try:
                ra, rb = _refit(law_a, opts_a, tg), _refit(law_b, opts_b, tg)
                row.append(ra.stats.chisqr - rb.stats.chisqr if ra.ok and rb.ok else math.nan)
            except FrictionLabError:
                row.append(math.nan)
        out.append(tuple(row))
    return out


def one_family(fit_a: FitResult, fit_b: FitResult) -> bool:
    """Whether the two laws are one model on this dataset: each spans the whole of one closed-form family
    with one solver (``ranking.family_key``; wear and Couette, F = k A u). Then each law's refit to any
    replicate is the other's (the same least-squares problem in k), so T* = 0 on every replicate and
    the test needs no refits."""
    from .ranking import family_key

    key = family_key(fit_a)
    return key is not None and key == family_key(fit_b) and _refit_options(fit_a)["free"].keys() == \
        _refit_options(fit_b)["free"].keys()


def _seeds(seed: int, key: str, n: int):
    return np.random.SeedSequence([int(seed), zlib.crc32(key.encode())]).spawn(n)


# --- the test -------------------------------------------------------------------------------------
def analyze_equivalence(fit_a: FitResult, fit_b: FitResult, replicates: int = REPLICATES, seed: int = 0,
                        executor=None, chunk: int | None = None, timeout: float | None = None) -> EquivalenceResult:
    """Discrimination test of ``fit_a``'s law against ``fit_b``'s on their (common) dataset.

    replicates: R per null (Monte-Carlo error of a p-value about sqrt(p(1-p)/R)); seed: the draws
    depend on it and on the dataset and the pair only. executor: None (here) or anything with
    ``submit`` (see bootstrap.py); chunk: replicates per task (default R / 4); timeout: time budget of
    each refit in seconds (None: none), past which it counts as a failed refit."""
    base = dict(dataset=fit_a.datasets[0], law_a=fit_a.law, law_b=fit_b.law, solver_a=fit_a.solver,
                solver_b=fit_b.solver, replicates=int(replicates), seed=int(seed))
    if fit_a.datasets != fit_b.datasets or len(fit_a.datasets) != 1:
        raise FrictionLabError(f"equivalence: the two fits must be of one and the same dataset "
                               f"({', '.join(fit_a.datasets)} / {', '.join(fit_b.datasets)})")
    if not (fit_a.ok and fit_b.ok):
        bad = fit_a if not fit_a.ok else fit_b
        return EquivalenceResult(**base, status="skipped", reason=f"{bad.law} [{bad.solver}] {bad.status}: {bad.reason}")
    if replicates < MIN_REPLICATES:
        raise ParameterError(f"equivalence: replicates must be at least {MIN_REPLICATES} (so that a p-value can fall "
                             f"below {ALPHA:g}), got {replicates}")
    da, db = fit_a.per_dataset[0], fit_b.per_dataset[0]
    target = da.target
    n = int(target.y.size)
    dec = decomposition(fit_a) or decomposition(fit_b)
    fitted = {f.law: {k: p.value for k, p in f.params.items() if p.kind == "law"} for f in (fit_a, fit_b)}
    sig = np.asarray(target.sigma, dtype=float)
    common = dict(n_points=n, observable=target.observable, sigma=float(np.max(sig)),
                  sigma_varies=bool(np.ptp(sig) > 1e-12 * np.max(sig)), fitted=fitted, decomposition=dec,
                  chi2={fit_a.law: fit_a.stats.chisqr, fit_b.law: fit_b.stats.chisqr},
                  k={fit_a.law: fit_a.stats.n_params, fit_b.law: fit_b.stats.n_params})
    d_ab, d_ba = cross_chi2(fit_a, fit_b, timeout), cross_chi2(fit_b, fit_a, timeout)
    threshold = _threshold(d_ab, d_ba, n, common["sigma"])
    opts_a, opts_b = (_refit_options(f) | {"timeout": timeout} for f in (fit_a, fit_b))
    seeds = _seeds(seed, f"{base['dataset']}|{fit_a.law}[{fit_a.solver}]|{fit_b.law}[{fit_b.solver}]", replicates)
    chunk = max(1, int(chunk or math.ceil(replicates / 4)))
    groups = [seeds[i:i + chunk] for i in range(0, replicates, chunk)]
    args = (fit_a.law, opts_a, fit_b.law, opts_b, target, da.model, db.model)
    if one_family(fit_a, fit_b):  # one model: both refits of every replicate are the same fit, T* = 0
        rows = [(0.0, 0.0)] * replicates
    elif executor is None:
        rows = [r for g in groups for r in _replicate_chunk(*args, g)]
    else:
        futures = [executor.submit(_replicate_chunk, *args, g) for g in groups]
        rows = [r for fut in futures for r in fut.result()]
    arr = np.array(rows, dtype=float).reshape(-1, 2)
    t_a, t_b = arr[np.isfinite(arr[:, 0]), 0], arr[np.isfinite(arr[:, 1]), 1]
    failed = int(np.sum(~np.isfinite(arr)))
    t_obs = float(fit_a.stats.chisqr - fit_b.stats.chisqr)
    res = dict(**base, **common, t_obs=t_obs, t_a=t_a, t_b=t_b, failed=failed, d_ab=d_ab, d_ba=d_ba,
               threshold=threshold)
    if min(t_a.size, t_b.size) < max(MIN_REPLICATES, replicates // 2):
        return EquivalenceResult(**res, status="failed",
                                 reason=f"{failed} of {2 * replicates} replicate refits failed: too few to test")
    tol = TIE_REL * max(n, fit_a.stats.chisqr, fit_b.stats.chisqr)
    p_a = _p_upper(t_a, t_obs, tol)
    p_b = _p_upper(-t_b, -t_obs, tol)
    crit_a, crit_b = float(np.quantile(t_a, 1 - ALPHA)), float(np.quantile(t_b, ALPHA))
    power_a = float(np.mean(t_b > crit_a + tol))  # data from B that reject A
    power_b = float(np.mean(t_a < crit_b - tol))  # data from A that reject B
    res.update(p_a=p_a, p_b=p_b, power_a=power_a, power_b=power_b, q_a=_p_upper(-t_a, -t_obs, tol),
               q_b=_p_upper(t_b, t_obs, tol))
    verdict, why = _verdict(EquivalenceResult(**res, status="ok"))
    if one_family(fit_a, fit_b):
        why += (" Both laws span one closed-form family here (one model), so each replicate's two refits are the "
                "same fit and T* = 0 on every replicate, without refitting.")
    return EquivalenceResult(**res, status="ok", verdict=verdict, explanation=why)


def _p_upper(sample: np.ndarray, x: float, tol: float) -> float:
    """(1 + #{sample > x} + #{ties} / 2) / (m + 1): the bootstrap p-value of x in the upper tail."""
    above = float(np.sum(sample > x + tol))
    ties = float(np.sum(np.abs(sample - x) <= tol))
    return (1.0 + above + 0.5 * ties) / (sample.size + 1.0)


def _threshold(d_ab: float, d_ba: float, n: int, sigma: float) -> float:
    """sigma at which the larger cross-fit chi-square reaches CRITICAL (0: the same curve; nan if unknown)."""
    if not (math.isfinite(d_ab) and math.isfinite(d_ba)):
        return math.nan
    d = max(d_ab, d_ba)
    if d <= TIE_REL * n:  # within the optimizer's resolution: one curve
        return 0.0
    return sigma * math.sqrt(d / CRITICAL)


def _verdict(e: EquivalenceResult) -> tuple[str, str]:
    a, b = f"{e.law_a} [{e.solver_a}]", f"{e.law_b} [{e.solver_b}]"
    m = min(e.t_a.size, e.t_b.size)
    pa = f"p = {e.p_a:.2g} ± {e.mc_error(e.p_a):.1g} under {a}"
    pb = f"p = {e.p_b:.2g} ± {e.mc_error(e.p_b):.1g} under {b}"
    head = (f"T = χ²({e.law_a}) − χ²({e.law_b}) = {e.t_obs:.4g} on the data; against {m} replicates from each fit "
            f"({pa}; {pb})")
    power = (f"the test rejects {a} on {100 * e.power_a:.0f}% of {b}'s replicates and {b} on "
             f"{100 * e.power_b:.0f}% of {a}'s")
    rej_a, rej_b = e.p_a < ALPHA, e.p_b < ALPHA
    thr = e.threshold_text()
    if rej_a or rej_b:
        if rej_a and rej_b:
            which = f"the data reject both {a} and {b} (T lies outside both null distributions)"
        else:
            bad, good = (a, b) if rej_a else (b, a)
            q = e.q_b if rej_a else e.q_a
            if q < ALPHA:
                which = (f"the data reject {bad}, and T lies beyond {good}'s replicates on its favourable side "
                         f"(p = {q:.2g}): the data are not like {good}'s either")
            else:
                which = f"the data reject {bad} and are consistent with {good}"
        return "not equivalent", f"{head}: {which}; {power}. {thr}."
    if max(e.power_a, e.power_b) < POWER:
        return "equivalent", (f"{head}: T is consistent with both and the two null distributions overlap ({power}): "
                              f"data of this noise cannot tell them apart. {thr}.")
    return "cannot tell at this noise", (f"{head}: T is consistent with both although {power}: "
                                         f"T falls where the two null distributions overlap. {thr}.")


# --- the first screen ------------------------------------------------------------------------------
def group_answer(results, datasets, pair: tuple[str, str] = PAIRS[0]) -> dict:
    """The equivalence fields of one group's ``answers.Answer`` from the tests of ``pair`` (default the
    paper's: wear against area-rate) on the member ``datasets`` (names): ``equivalence`` (the exact
    or numerical law), ``equivalence_series`` (the paper's series), ``noise_threshold`` (one
    sentence) and ``details`` (numbers per dataset). A group verdict is 'not equivalent' if any member
    tells the laws apart, 'equivalent' if every member says so, else 'cannot tell at this noise';
    'not tested' without a test."""
    names = set(datasets)
    mine = [e for e in results if e.dataset in names and (e.law_a, e.law_b) == pair]
    full = [e for e in mine if not e.involves_series]
    series = [e for e in mine if e.involves_series]

    def verdict(es):
        vs = [e.verdict for e in es if e.ok]
        if not vs:
            return "not tested"
        if "not equivalent" in vs:
            return "not equivalent"
        return "equivalent" if all(v == "equivalent" for v in vs) else "cannot tell at this noise"

    def thresholds(es):
        parts = []
        for e in es:
            if not math.isfinite(e.threshold):
                continue
            name, f = unit(e.observable)
            parts.append("at any noise (one curve)" if e.threshold == 0 else
                         f"when sigma < {_num(e.threshold * f)} {name} on {e.dataset} (sigma {_num(e.sigma * f)} {name})")
        return ", ".join(parts)

    def threshold_short(es):
        """'differ unless σ > 1.8 deg (σ = 0.5 deg)'; members joined by ' / ' in one unit."""
        es = [e for e in es if math.isfinite(e.threshold)]
        if not es:
            return ""
        if all(e.threshold == 0 for e in es):
            return "one curve: equal at any noise"
        name, f = unit(es[0].observable)
        same = len({e.observable for e in es}) == 1
        thr = " / ".join(_num2(e.threshold * f) if same else e.threshold_text() for e in es)
        sig = " / ".join(dict.fromkeys(_num2(e.sigma * f) for e in es))
        return f"differ unless σ > {thr} {name} (σ = {sig} {name})" if same else f"differ unless σ > {thr}"

    text = ""
    if thresholds(full):
        text = f"{pair[0]} and {pair[1]} differ by more than the noise {thresholds(full)}"
        if thresholds(series):
            text += f"; the paper's series of {pair[0]}: {thresholds(series)}"
    elif thresholds(series):
        text = f"the paper's series of {pair[0]} and {pair[1]} differ by more than the noise {thresholds(series)}"
    v_full, v_series = verdict(full), verdict(series)
    tested = [(v, how) for v, how in ((v_full, "exact"), (v_series, "series")) if v != "not tested"]
    short = {"equivalence": (f"{v_full} (exact and series)" if len(tested) == 2 and v_full == v_series else
                             "; ".join(f"{v} ({how})" for v, how in tested) or "not tested")}
    if threshold_short(full or series):
        short["threshold"] = threshold_short(full or series) + ("" if full else " [series]")
    return {"equivalence": v_full, "equivalence_series": v_series, "noise_threshold": text, "short": short,
            "details": {"equivalence": [e.as_dict() | {"t_a": None, "t_b": None} for e in mine]}}


def fill_answers(answers, results) -> tuple:
    """``answers`` (answers.Answer rows) with their equivalence fields filled from the tests ``results``."""
    out = []
    for a in answers:
        g = group_answer(results, a.datasets)
        out.append(attrs.evolve(a, equivalence=g["equivalence"], equivalence_series=g["equivalence_series"],
                                noise_threshold=g["noise_threshold"], details={**a.details, **g["details"]},
                                short={**a.short, **g["short"]}))
    return tuple(out)
