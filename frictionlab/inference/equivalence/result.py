"""The equivalence test's result and its verdict (``decide``): the constants of the test, ``EquivalenceResult``
and the sentences that state it. The test itself is ``equivalence.analyze_equivalence``."""
from __future__ import annotations

import math

import attrs
import numpy as np

from ...core.display import unit
from .decomposition import Decomposition
from .qualitative import text as qual_text

WEAR, AREA_RATE, COUETTE, COULOMB = "wear", "area-rate", "couette", "coulomb"
#: The pairs ``compare`` tests by default: the paper's claim, the structural identity, and the simplest law against the paper's.
PAIRS = ((WEAR, AREA_RATE), (WEAR, COUETTE), (COULOMB, WEAR))
ALPHA = 0.05  # level of every test of a report (family-wise, Holm): different, and equivalent within delta
CRITICAL = 3.84  # chi-square (1 dof, 95%) by which a cross-fit misses at the threshold noise
#: The tightest margin, in noise sigmas, at which 'equivalent within delta' is said where the replicates' distances
#: vary: benchmarks/calibration.py measured the bound below delta where the curves differ by delta in at most 6%
#: of datasets at delta = 1 sigma, and in 23% at 0.25 sigma (the fitted curves' own uncertainty, not the bound's
#: spread, then decides the distance): a tighter margin gets 'cannot tell', saying why.
MIN_MARGIN = 1.0
REPLICATES = 400  # the most replicates per null (sequential: clear cases stop after a batch or two)
BATCH = 20  # replicates per null drawn between stopping checks
MIN_REPLICATES = 20  # the smallest allowed maximum
CI_LEVEL = 0.99  # Clopper-Pearson interval of a Monte-Carlo p-value that decides when to stop
FAR_MIN = 40  # replicates before T beyond all of a law's may stop sampling by its tail estimate
TAIL_Q = 0.75  # the exponential tail is fitted to the replicates above this quantile
TAIL_CONF = 0.95  # ... with its scale (mean excess) at this upper confidence bound
FAR_P = ALPHA / 20  # ... when that tail puts T's p below this (clear of any Holm level up to 10 members)
TAIL_FLOOR = 1e-6  # a tail estimate is extrapolation: smaller values are reported as this bound
TIE_REL = 1e-4  # |T* - T| below this fraction of max(n, chi2) is a tie (the optimizer's resolution)
DIFFERENT, WITHIN, CANNOT, BOTH_FAIL = ("different", "equivalent within δ", "cannot tell at this noise",
                                        "both fail their fit tests")
#: The answers of one test: the three of a valid test, and no test where both laws fail their fit tests.
VERDICTS = (DIFFERENT, WITHIN, CANNOT, BOTH_FAIL)
#: The family a single test's p-values are adjusted in when nobody adjusts them together.
ALONE = "this test alone"


@attrs.frozen(eq=False)
class EquivalenceResult:
    """The test of law A against law B on one dataset (what `analyze_equivalence` returns; `compare` gives
    one per tested pair in ``Comparison.equivalence``). SI units; for stated numbers, stated precisions.

    Attributes
    ----------
    dataset, law_a, law_b, solver_a, solver_b : str
        What was tested.
    status : {"ok", "skipped", "failed"}
        Whether the test ran; ``reason`` says why not.
    verdict : str
        One of ``VERDICTS``: "different", "equivalent within δ", "cannot tell at this noise", or "both fail
        their fit tests" (then ``closer`` says which law is nearer the data by Vuong's test).
    explanation : str
        The verdict in sentences.
    p, p_adjusted : float
        Two-sided p-value of "neither law is rejected", before and after the family's Holm adjustment.
    rms, upper : float
        The RMS difference of the two best curves and its upper confidence bound, in the observable's unit.
    margin : float
        The margin delta, in the observable's unit; ``margin_text`` says how it was chosen.
    p_within, p_within_adjusted : float
        p-value of "the curves differ by delta or more", before and after adjustment.
    chi2, fits : dict
        Each law's chi-square on the data, and whether it passes its own fit tests.
    statistic, closer : str
        The statistic the verdict rests on, and, where both laws fail their fit tests, which law is closer to
        the data (Vuong's non-nested test with a HAC variance) or that they are equally close at this noise.
    """

    dataset: str
    law_a: str
    law_b: str
    solver_a: str
    solver_b: str
    status: str  # ok | skipped | failed
    verdict: str = ""  # one of VERDICTS when status is ok
    explanation: str = ""
    reason: str = ""
    replicates: int = 0  # the most replicates per null
    seed: int = 0
    n_points: int = 0
    chi2: dict = attrs.field(factory=dict)  # law -> chi2 on the data (``statistic``: -2 ln L where profiled)
    k: dict = attrs.field(factory=dict)  # law -> identifiable parameters
    t_obs: float = math.nan  # chi2_A - chi2_B on the data (``statistic``)
    t_a: np.ndarray = attrs.field(factory=lambda: np.zeros(0))  # T on replicates of A's fit (failed refits dropped)
    t_b: np.ndarray = attrs.field(factory=lambda: np.zeros(0))  # T on replicates of B's fit
    c_a: float = math.nan  # B refitted to A's best curve: T's location under A is -c_a
    c_b: float = math.nan  # A refitted to B's best curve: T's location under B is c_b
    s_a: np.ndarray = attrs.field(factory=lambda: np.zeros(0))  # S_A = T + c_a on A's replicates (own refits' c_a)
    s_b: np.ndarray = attrs.field(factory=lambda: np.zeros(0))  # S_B = T - c_b on B's replicates
    p_a: float = math.nan  # P(S_A* >= S_A | A): small rejects A
    p_b: float = math.nan  # P(S_B* <= S_B | B): small rejects B
    q_a: float = math.nan  # P(S_A* <= S_A | A): small means the data lie beyond A's replicates on A's favourable side
    q_b: float = math.nan  # P(S_B* >= S_B | B): likewise for B
    p: float = math.nan  # two-sided: min(1, 2 min(p_A, p_B)); nan when both laws fail their fit tests
    power_a: float = math.nan  # share of B's replicates that reject A at ALPHA / 2
    power_b: float = math.nan  # share of A's replicates that reject B at ALPHA / 2
    failed: int = 0  # replicates dropped because a refit failed
    stopped: str = ""  # why sampling stopped
    d_ab: float = math.nan  # A refitted to B's best curve: chi2 at the sigma used
    d_ba: float = math.nan  # B refitted to A's best curve
    sigma: float = math.nan  # sigma of the observable the likelihood uses (SI; the largest if it varies)
    sigma_varies: bool = False
    noise: str = ""  # the likelihood's noise kind: known | estimated | stated
    observable: str = ""
    rms: float = math.nan  # RMS difference of the two best curves (SI; 'stated': in stated precisions)
    fits: dict = attrs.field(factory=dict)  # law -> passes its own fit tests (True / False / None)
    goodness: dict = attrs.field(factory=dict)  # law -> its fit tests' reason (one phrase)
    qualitative: dict = attrs.field(factory=dict)  # qualitative.qualitative: shared curve features
    fitted: dict = attrs.field(factory=dict)  # law -> {param: SI value}
    decomposition: Decomposition | None = None  # the paper's decomposition (wear [series] only)
    margin: float = math.nan  # delta (SI; 'stated': stated precisions)
    margin_text: str = ""  # 'δ = 1 × σ = 0.003 m/s (the default margin)'
    margin_relative: bool = True  # delta is a multiple of the noise (re-estimated per replicate where estimated)
    margin_sigmas: float = math.nan  # delta over the noise sigma (RMS; 'stated': delta itself, in stated precisions)
    x_a: np.ndarray = attrs.field(factory=lambda: np.zeros(0))  # distance / delta of the refitted curves, A's replicates
    x_b: np.ndarray = attrs.field(factory=lambda: np.zeros(0))  # ... on B's replicates
    x_null_a: float = math.nan  # A's best curve against B refitted to it, / delta: the distance if A is the truth
    x_null_b: float = math.nan  # B's best curve against A refitted to it, / delta
    upper: float = math.nan  # upper (1 - ALPHA) bound of the distance (SI; 'stated': stated precisions)
    p_within: float = math.nan  # p-value of 'the curves differ by delta or more'
    p_adjusted: float = math.nan  # p after the family's adjustment (Holm)
    p_within_adjusted: float = math.nan
    family: str = ALONE  # the family the p-values were adjusted in
    #: The statistic of ``chi2`` and ``t_obs``: 'χ²' at the noise the likelihood uses, or '−2 ln L' where each fit
    #: profiles its noise model with the law (the data's AR(p): chi-square is n there).
    statistic: str = "χ²"
    closer: str = ""  # Vuong's test of which law is closer (``vuong``), where each fit has pointwise log-likelihoods

    @property
    def ok(self) -> bool:
        """True when the test was run (status 'ok')."""
        return self.status == "ok"

    @property
    def tested(self) -> bool:
        """Whether the pair got p-values (ok, and not both laws failing their fit tests)."""
        return self.ok and self.verdict != BOTH_FAIL

    @property
    def label(self) -> str:
        """'law A [solver] vs law B [solver] on DATASET'."""
        return f"{self.law_a} [{self.solver_a}] vs {self.law_b} [{self.solver_b}]"

    @property
    def involves_series(self) -> bool:
        """True when one side is the paper's truncated series."""
        return "series" in (self.solver_a, self.solver_b)

    @property
    def within(self) -> bool:
        """Whether the curves are shown to lie within delta (after the family's adjustment)."""
        return self.tested and self.p_within_adjusted < ALPHA

    def scale(self, d: float) -> float:
        """The noise at which a cross-fit leaving chi-square ``d`` misses by ``CRITICAL``.

        Parameters
        ----------
        d : float
            A cross-fit's chi-square at the sigma used (``d_ab`` or ``d_ba``).

        Returns
        -------
        float
            That noise as a multiple of the sigma used (0: one curve; nan if ``d`` is not finite).
        """
        if not math.isfinite(d):
            return math.nan
        return 0.0 if d <= TIE_REL * max(self.n_points, 1) else math.sqrt(d / CRITICAL)

    @property
    def threshold(self) -> float:
        """The larger of the two threshold noises (SI; 0: one curve; nan if unknown): below it at least
        one direction is detected about half the time."""
        return max(self.scale(self.d_ab), self.scale(self.d_ba)) * self.sigma

    def mc_error(self, p: float) -> float:
        """The Monte-Carlo standard error of a p-value from the replicates drawn.

        Parameters
        ----------
        p : float
            A p-value of this test.

        Returns
        -------
        float
            sqrt(p (1 - p) / m), m the replicates per law; nan for a p that is not finite.
        """
        m = min(self.s_a.size, self.s_b.size) or 1
        return math.sqrt(max(p * (1 - p), 0.0) / m) if math.isfinite(p) else math.nan

    def quantity(self, x: float) -> str:
        """A distance as text in the observable's display unit.

        Parameters
        ----------
        x : float
            A distance, SI (for stated numbers, in stated precisions).

        Returns
        -------
        str
            ``"0.078 m/s"``, ``"13.2 stated precisions"``.
        """
        if self.observable == "stated":
            return f"{_num(x)} stated precision{'s' * (abs(x) != 1)}"
        name, f = unit(self.observable)
        return f"{_num(x * f)} {name}"

    def _noise(self, s: float) -> str:
        if self.observable == "stated":
            return f"{_num(s)} × the stated precision"
        name, f = unit(self.observable)
        return f"σ = {_num(s * self.sigma * f)} {name}"

    def threshold_text(self) -> str:
        """Both directions of the noise threshold, with the curves' RMS difference beside them.

        Returns
        -------
        str
            One sentence; "" when a threshold is unknown.
        """
        sa, sb = self.scale(self.d_ab), self.scale(self.d_ba)
        if not (math.isfinite(sa) and math.isfinite(sb)):
            return ""
        a, b = f"{self.law_a} [{self.solver_a}]", f"{self.law_b} [{self.solver_b}]"
        if sa == 0.0 and sb == 0.0:
            return f"one curve: {a} and {b} give the same curve, indistinguishable at any noise"
        if self.observable == "stated":
            used, rms = "the stated precision", f"{_num(self.rms)} stated precisions"
        else:
            name, f = unit(self.observable)
            used = f"σ used: {_num(self.sigma * f)} {name}{' (largest)' if self.sigma_varies else ''}, {self.noise}"
            rms = f"{_num(self.rms * f)} {name}"
        return (f"a fit of {a} to {b}'s curve misses it by χ² {CRITICAL:g} (about 50% power to reject {self.law_a}) "
                f"at {self._noise(sa)}, of {b} to {a}'s at {self._noise(sb)} ({used}); the two best curves differ "
                f"by {rms} RMS")

    def as_dict(self) -> dict:
        """The result as plain values.

        Returns
        -------
        dict
            Every field (arrays as lists) and the derived numbers, as ``results.json`` records them.
        """
        d = {k: v for k, v in attrs.asdict(self, recurse=False).items() if k != "decomposition"}
        for k in ("t_a", "t_b", "s_a", "s_b", "x_a", "x_b"):
            d[k] = getattr(self, k).tolist()
        d["s_obs_a"], d["s_obs_b"] = self.t_obs + self.c_a, self.t_obs - self.c_b
        d["p_a_mc_error"], d["p_b_mc_error"] = self.mc_error(self.p_a), self.mc_error(self.p_b)
        d["alpha"], d["critical_dchi2"] = ALPHA, CRITICAL
        d["threshold"], d["threshold_ab"], d["threshold_ba"] = (self.threshold, self.scale(self.d_ab) * self.sigma,
                                                                self.scale(self.d_ba) * self.sigma)
        d["threshold_text"] = self.threshold_text()
        d["within"] = self.within
        d["decomposition"] = self.decomposition.as_dict() if self.decomposition else None
        return d


def _num(x: float) -> str:
    return f"{x:,.0f}" if abs(x) >= 100 else f"{x:.3g}"


def sentence(text: str) -> str:
    """``text`` as one sentence: a plain first word capitalized (never a name: a registered law, a dataset or a
    symbol such as chi2, eta' or impact-golf-v28 stays as written), one full stop at the end ('' stays '')."""
    import re

    from ...physics.registry import available_laws

    text = text.strip()
    if not text:
        return ""
    m = re.match(r"[a-z]+(?=[\s,:;.)]|$)", text)
    if m and m.group(0) not in available_laws():
        text = text[0].upper() + text[1:]
    return text if text.endswith((".", "!", "?")) else text + "."


def sentences(*parts: str) -> str:
    """Sentences joined by spaces, each made whole by ``sentence`` (empty parts dropped)."""
    return " ".join(s for s in (sentence(p) for p in parts) if s)


# --- the test -------------------------------------------------------------------------------------


def _p(p: float) -> str:
    return f"{p:.2g}"


def decide(e: EquivalenceResult) -> EquivalenceResult:
    """``e`` with its verdict and explanation decided from its (family-adjusted) p-values: sentences built
    from whole parts, each ending in a full stop."""
    a, b = f"{e.law_a} [{e.solver_a}]", f"{e.law_b} [{e.solver_b}]"
    quali = qual_text(e.qualitative, e.law_a, e.law_b) if e.qualitative.get("verdict") not in (None, "not applicable") \
        else ""
    tail = [e.threshold_text(), f"qualitatively (shared curve features): {quali}" if quali else ""]
    if one_family_result(e):
        tail.append("both laws span one closed-form family here (one model), so each replicate's two refits are the "
                    "same fit and T* = 0 on every replicate, without refitting")
    if e.fits.get(e.law_a) is False and e.fits.get(e.law_b) is False:
        better = e.law_a if e.chi2[e.law_a] < e.chi2[e.law_b] else e.law_b
        worse = e.law_b if better == e.law_a else e.law_a
        d_aic = (e.chi2[worse] - e.chi2[better]) + 2 * (e.k[worse] - e.k[better])
        what = "stated numbers" if e.observable == "stated" else "points"
        gap = e.chi2[worse] - e.chi2[better]
        stat = e.statistic
        less = (f"{better} misses less (Δ{stat} = {_num(gap)}, ΔAIC = {_num(d_aic)}), which says which description is "
                "less poor, not that either holds" if gap > TIE_REL * max(e.n_points, abs(e.chi2[better]))
                else "they miss equally (one curve)")
        if e.closer:
            less = f"which is closer, a test valid when both miss: {e.closer}"
        text = sentences(
            f"no test: {a} and {b} both fail their own fit tests ({e.law_a}: {e.goodness.get(e.law_a) or 'fails'}; "
            f"{e.law_b}: {e.goodness.get(e.law_b) or 'fails'}), so neither is a valid null for the other and the pair "
            "gets no p-value",
            f"their misfits: {e.statistic} = {_num(e.chi2[e.law_a])} ({e.law_a}) and {_num(e.chi2[e.law_b])} "
            f"({e.law_b}) over {e.n_points} {what}; {less}",
            f"the two best curves differ by {e.quantity(e.rms)} RMS (the margin: {e.margin_text})", *tail)
        return attrs.evolve(e, verdict=BOTH_FAIL, explanation=text, p=math.nan, p_adjusted=math.nan,
                            p_within=math.nan, p_within_adjusted=math.nan)
    m = min(e.t_a.size, e.t_b.size)
    adjusted = "" if e.family == ALONE else f" ({e.family}: adjusted p = {_p(e.p_adjusted)})"
    st = e.statistic
    head = (f"T = {st}({e.law_a}) − {st}({e.law_b}) = {e.t_obs:.4g} on the data ({e.noise} σ), centred at its location "
            f"under each fit ({e.t_obs + e.c_a:.3g} under {e.law_a}, {e.t_obs - e.c_b:.3g} under {e.law_b}); against {m} "
            f"replicates from each fit ({e.stopped}): p = {_p(e.p_a)} ± {e.mc_error(e.p_a):.1g} under {a}, "
            f"p = {_p(e.p_b)} ± {e.mc_error(e.p_b):.1g} under {b}; two-sided p = {_p(e.p)}{adjusted} at α = {ALPHA:g}")
    power = (f"the test rejects {a} on {100 * e.power_a:.0f}% of {b}'s replicates and {b} on "
             f"{100 * e.power_b:.0f}% of {a}'s")
    different = e.p_adjusted < ALPHA
    if different:
        rej_a = e.p_a <= e.p_b
        bad, good = (a, b) if rej_a else (b, a)
        good_law = e.law_b if rej_a else e.law_a
        q = e.q_b if rej_a else e.q_a
        own = e.p_b if rej_a else e.p_a  # the kept law's own p: below alpha / 2 it is rejected too
        if own < ALPHA / 2:
            which = (f"the data reject {bad}, and {good} too (p = {_p(own)} under {good}, below α/2): "
                     "the data are like neither")
        elif q < ALPHA / 2:
            which = (f"the data reject {bad}, and lie beyond {good}'s replicates on its favourable side "
                     f"(p = {_p(q)}): the data are not like {good}'s either")
        elif e.fits.get(good_law) is False:
            which = f"the data reject {bad} against {good}, but {good} fails its own fit tests: the data are like neither"
        else:
            which = f"the data reject {bad} and are consistent with {good}"
    else:
        unfit = [f"{law} fails its own fit tests" for law, ok in e.fits.items() if ok is False]
        which = "T rejects neither law" + (f" ({'; '.join(unfit)})" if unfit else "")
    inside = e.p_within_adjusted < ALPHA
    adjusted_w = "" if e.family == ALONE else f", adjusted {_p(e.p_within_adjusted)}"
    dist = (f"the two best curves differ by {e.quantity(e.rms)} RMS; the upper {1 - ALPHA:.0%} bound of that "
            f"distance, {e.quantity(e.upper) if math.isfinite(e.upper) else 'not available'}, "
            f"{'lies below' if inside else 'does not lie below'} the margin {e.margin_text} (p = {_p(e.p_within)}"
            f"{adjusted_w} for a distance of δ or more)")
    if different:
        verdict = DIFFERENT
        say = ("so: different, though by less than δ: the data tell the laws apart, but their curves lie within the "
               "margin" if inside else "so: different")
    elif inside and e.margin_sigmas < MIN_MARGIN * (1 - 1e-9) and not one_family_result(e):
        verdict, say = CANNOT, (f"so: cannot tell at this noise: neither law is rejected, and δ is {e.margin_sigmas:.2g} "
                                f"σ, tighter than the {MIN_MARGIN:g} σ below which a bound of the distance is not "
                                "calibrated (the fitted curves' own uncertainty decides it there)")
    elif inside:
        verdict, say = WITHIN, (f"so: equivalent within δ: neither law is rejected and their curves are shown to lie "
                                f"within {e.margin_text.split(', ')[0]}")
    else:
        verdict, say = CANNOT, ("so: cannot tell at this noise: neither law is rejected, and the curves are not shown "
                                "to lie within δ")
    beside = f"beside it, Vuong's test of which law is closer: {e.closer}" if e.closer else ""
    return attrs.evolve(e, verdict=verdict, explanation=sentences(head, which, dist, say, power, beside, *tail))


def one_family_result(e: EquivalenceResult) -> bool:
    """Whether ``e`` was decided by the one-model shortcut (``one_family``)."""
    return e.stopped.startswith("one model")
