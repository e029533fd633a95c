"""The result of one equivalence test (law A against law B on one dataset), its verdicts and the levels they
are decided at; the test itself is in ``discrimination``."""
from __future__ import annotations

import math

import attrs
import numpy as np

from ...core.display import unit
from .decomposition import Decomposition

ALPHA = 0.05  # level of every test of a report (family-wise, Holm): different, and equivalent within delta
CRITICAL = 3.84  # chi-square (1 dof, 95%) by which a cross-fit misses at the threshold noise
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
        their fit tests" (then no p-value: the misfits are compared instead).
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
    chi2: dict = attrs.field(factory=dict)  # law -> chi2 on the data
    k: dict = attrs.field(factory=dict)  # law -> identifiable parameters
    t_obs: float = math.nan  # chi2_A - chi2_B on the data
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
            return f"{number_text(x)} stated precision{'s' * (abs(x) != 1)}"
        name, f = unit(self.observable)
        return f"{number_text(x * f)} {name}"

    def _noise(self, s: float) -> str:
        if self.observable == "stated":
            return f"{number_text(s)} × the stated precision"
        name, f = unit(self.observable)
        return f"σ = {number_text(s * self.sigma * f)} {name}"

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
            used, rms = "the stated precision", f"{number_text(self.rms)} stated precisions"
        else:
            name, f = unit(self.observable)
            used = f"σ used: {number_text(self.sigma * f)} {name}{' (largest)' if self.sigma_varies else ''}, {self.noise}"
            rms = f"{number_text(self.rms * f)} {name}"
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


def number_text(x: float) -> str:
    """A number as the equivalence texts write it: thousands grouped from 100 up, else 3 significant digits."""
    return f"{x:,.0f}" if abs(x) >= 100 else f"{x:.3g}"
