"""The paper's claim, tested: lambda A u is "qualitatively equivalent" to mu N + mu eta' dA/dt.

For one dataset and one solver of the wear law, ``analyze_equivalence`` takes the best fits of
both laws and asks four checkable questions:

1. Fit to the data: chi-square, AIC of each (from the fits).
2. Cross-fits: each law fitted to the other's best-fit curve (same times, same noise weights).
   The RMS misfit in units of the data's noise says whether data of this quality could ever
   tell the two apart (<= 1 sigma: indistinguishable).
3. Force histories: Pearson correlation r and the normalized RMS distance
   d = rms(F_wear - F_ar) / sqrt((rms(F_wear)^2 + rms(F_ar)^2) / 2) over the contact.
4. The paper's decomposition: with u ~ u0 (1 - b + b cos phi t) (eq 7) and A = A0 sin phi t,
   lambda A u = lambda u0 (1 - b) A + (lambda u0 b / (phi A0)) A dA/dt. The paper prints the
   second factor as phi/A0 ("cos phi t = (phi/A0) dA/dt"); dimensionally cos phi t =
   dA/dt / (phi A0). Projected by least squares onto mu N + mu eta' dA/dt over the contact, it
   gives the mu and eta' the claim implies; they are compared with the fitted area-rate values.
   (With a half-sine N of the same contact time: mu = lambda u0 (1-b) A0 / N0 and
   mu eta' = lambda u0 b (4 / (3 pi)) / phi, since the projection of A dA/dt on dA/dt is 4 A0 / (3 pi).)

Verdict: 'equivalent at this noise' if both cross-fits come within 1 noise sigma (RMS);
else 'qualitatively similar' if the fitted curves have the same shape (both fall after their
peak, or neither does), the forces correlate (r >= R_SIMILAR) and, where the decomposition
applies, the implied mu and eta' are within a factor FACTOR of the fitted ones; otherwise
'not equivalent', naming the checks that failed.
"""
from __future__ import annotations

import math

import attrs
import numpy as np

from .display import fmt_time
from .fitting import FitResult, Target, fit
from .law import AreaSlipForm
from .registry import get_law
from .scene import HalfSineArea

WEAR, AREA_RATE = "wear", "area-rate"
R_SIMILAR = 0.8  # force correlation from which two force histories count as similar
FACTOR = 2.0  # implied and fitted area-rate parameters agree if within this factor (same sign)
FALL = 0.05  # a curve "falls after its peak" if it ends more than 5% below its maximum


@attrs.frozen
class CrossFit:
    """Law ``law`` fitted to the best-fit curve of law ``to``: misfit in data units and in noise sigmas."""

    law: str
    to: str
    status: str
    rms: float = math.nan  # [observable SI]
    rms_sigma: float = math.nan  # rms / noise
    params: dict = attrs.field(factory=dict)  # SI


@attrs.frozen
class Decomposition:
    """The paper's two-term form of lambda A u, and its projection onto mu N + mu eta' dA/dt."""

    b: float
    u0: float  # [m/s]
    c_area: float  # lambda u0 (1 - b) [N/m^2]
    c_area_rate: float  # lambda u0 b / (phi A0) [N s/m^4]
    mu: float  # implied mu [-]
    eta_prime: float  # implied eta' [N s/m^2]
    r2: float  # share of the decomposition force the projection reproduces


@attrs.frozen
class EquivalenceResult:
    dataset: str
    solver: str  # of the wear law; area-rate uses its own (exact where it exists, else ode)
    area_rate_solver: str
    status: str  # ok | skipped
    verdict: str = ""
    explanation: str = ""
    reason: str = ""
    aic: dict = attrs.field(factory=dict)  # law -> AIC on the data
    redchi: dict = attrs.field(factory=dict)
    cross: tuple[CrossFit, ...] = ()
    force_correlation: float = math.nan
    force_distance: float = math.nan
    impulse: dict = attrs.field(factory=dict)  # law -> integral of F over the record [N s]
    shape: dict = attrs.field(factory=dict)  # law -> description of its fitted curve
    fitted: dict = attrs.field(factory=dict)  # law -> {param: SI value}
    decomposition: Decomposition | None = None
    checks: dict = attrs.field(factory=dict)  # check -> passed


def _shape(t: np.ndarray, y: np.ndarray) -> tuple[bool, str]:
    """Does the curve fall after its peak (by more than FALL of its maximum)? With a description."""
    i = int(np.argmax(y))
    scale = float(np.max(np.abs(y))) or 1.0
    drop = (float(y[i]) - float(y[-1])) / scale
    if drop > FALL:
        return True, f"peaks at t = {fmt_time(float(t[i]), float(t[-1]))} and then falls by {100 * drop:.0f}%"
    return False, "rises throughout (no fall after a peak)"


def _cross(own: FitResult, other: FitResult) -> CrossFit:
    """Refit ``own``'s law to ``other``'s best-fit curve, starting from ``own``'s best parameters."""
    d = other.per_dataset[0]
    tg = Target(d.target.dataset, d.target.observable, d.model.copy(), d.target.sigma, f"best fit of {other.law}")
    start = {k: p.value for k, p in own.params.items() if p.kind == "law" and p.vary}
    law = own.law
    r = fit(law, tg, solver=own.per_dataset[0].solver, initial=start, scan=0, n_starts=1)
    if not r.ok:
        return CrossFit(law, other.law, r.status)
    mine = r.per_dataset[0]
    rms = mine.rmse
    return CrossFit(law, other.law, "ok", rms, float(np.sqrt(np.mean((mine.residual / tg.sigma) ** 2))),
                    {k: v.value for k, v in r.params.items() if v.kind == "law"})


def decomposition(fw: FitResult) -> Decomposition | None:
    """The paper's decomposition of the wear fit, projected onto mu N + mu eta' dA/dt, or None when
    the scene is not the half-sine impact (no A0, phi) or has no normal-force model."""
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


def _forces(fw: FitResult, fa: FitResult):
    t_end = fw.per_dataset[0].scene.duration
    t = np.linspace(0.0, t_end, 801)
    tw = fw.per_dataset[0].trajectory(get_law(fw.law), t)
    ta = fa.per_dataset[0].trajectory(get_law(fa.law), t)
    return t, tw.force, ta.force


def analyze_equivalence(fw: FitResult, fa: FitResult, cross: bool = True) -> EquivalenceResult:
    """Equivalence analysis of a wear fit ``fw`` and an area-rate fit ``fa`` of the same dataset."""
    dataset = fw.datasets[0]
    base = dict(dataset=dataset, solver=fw.solver, area_rate_solver=fa.solver)
    if not (fw.ok and fa.ok):
        bad = fw if not fw.ok else fa
        return EquivalenceResult(**base, status="skipped", reason=f"{bad.law} [{bad.solver}] {bad.status}: {bad.reason}")
    if fw.per_dataset[0].target.t is None:
        return EquivalenceResult(**base, status="skipped", reason="the dataset has no time series to compare forces on")
    t, Fw, Fa = _forces(fw, fa)
    r = float(np.corrcoef(Fw, Fa)[0, 1]) if np.std(Fw) > 0 and np.std(Fa) > 0 else math.nan
    rms = lambda x: float(np.sqrt(np.mean(x**2)))  # noqa: E731
    dist = rms(Fw - Fa) / max(math.sqrt((rms(Fw) ** 2 + rms(Fa) ** 2) / 2), 1e-300)
    impulse = {WEAR: float(np.trapezoid(Fw, t)), AREA_RATE: float(np.trapezoid(Fa, t))}
    crosses = ()
    if cross:
        crosses = (_cross(fa, fw), _cross(fw, fa))
    falls = {}
    shape = {}
    for f in (fw, fa):
        falls[f.law], shape[f.law] = _shape(f.per_dataset[0].target.t, f.per_dataset[0].model)
    dec = decomposition(fw)
    verdict, why, checks = _verdict(crosses, r, dist, falls, shape, fw, fa, dec)
    return EquivalenceResult(
        **base, status="ok", verdict=verdict, explanation=why,
        aic={fw.law: fw.stats.aic, fa.law: fa.stats.aic}, redchi={fw.law: fw.stats.redchi, fa.law: fa.stats.redchi},
        cross=crosses, force_correlation=r, force_distance=dist, impulse=impulse, shape=shape,
        fitted={f.law: {k: p.value for k, p in f.params.items() if p.kind == "law"} for f in (fw, fa)},
        decomposition=dec, checks=checks)


def _verdict(crosses, r, dist, falls, shape, fw, fa, dec) -> tuple[str, str, dict]:
    """The verdict, the sentence behind it, and each check with its outcome."""
    checks = {}
    ok_cross = [c for c in crosses if c.status == "ok"]
    checks["cross-fits within the noise"] = len(crosses) == 2 and all(c.rms_sigma <= 1.0 for c in ok_cross) \
        and len(ok_cross) == 2
    checks["same curve shape"] = falls[WEAR] == falls[AREA_RATE]
    checks[f"force correlation r >= {R_SIMILAR}"] = bool(r >= R_SIMILAR)
    if dec is not None:
        mu_a, eta_a = fa.value("mu"), fa.value("eta_prime")
        ratios = [dec.mu / mu_a if mu_a else math.inf, dec.eta_prime / eta_a if eta_a else math.inf]
        checks[f"implied mu and eta' within a factor {FACTOR:g} of the fitted ones"] = all(
            1 / FACTOR <= q <= FACTOR for q in ratios)
    parts = [f"forces correlate at r = {r:.3f} (normalized distance {dist:.2f})"]
    for c in crosses:
        parts.append(f"{c.law} refitted to {c.to}'s best curve misses it by {c.rms_sigma:.2f} noise sigma (RMS)"
                     if c.status == "ok" else f"{c.law} could not be refitted to {c.to}'s curve ({c.status})")
    parts.append(f"wear [{fw.solver}] {shape[WEAR]}; area-rate [{fa.solver}] {shape[AREA_RATE]}")
    if dec is not None:
        parts.append(f"the paper's decomposition of the wear fit (b = {dec.b:.3g}) implies mu = {dec.mu:.3g} and "
                     f"eta' = {dec.eta_prime:.4g} N s/m^2 against fitted mu = {fa.value('mu'):.3g} and "
                     f"eta' = {fa.value('eta_prime'):.4g} N s/m^2 (projection R^2 = {dec.r2:.2f})")
    if checks["cross-fits within the noise"]:
        verdict = "equivalent at this noise"
        parts.append("each law reproduces the other's fitted curve within the noise: these data cannot tell them apart")
    else:
        failed = [k for k, v in checks.items() if not v and k != "cross-fits within the noise"]
        if not failed:
            verdict = "qualitatively similar"
            parts.append("same shape, correlated forces" + (", consistent implied parameters" if dec else "")
                         + "; but the data tell the two laws apart")
        else:
            verdict = "not equivalent"
            parts.append("fails: " + "; ".join(failed))
    return verdict, "; ".join(parts) + ".", checks
