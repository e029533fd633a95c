"""Fit statistics from the likelihood a dataset's noise calls for, and the parameter results (see ``fitting``)."""
from __future__ import annotations

import math

import numpy as np

from .result import ParamResult, Stats
from ..diagnostics.identifiability import in_ratio


#: Likelihoods whose sigma is used as given (no parameter of the fit): measured, estimated without a
#: law, or the stated precision of a reconstruction's stated numbers.
AS_GIVEN = ("known", "estimated", "stated")


def noise_kind(target) -> str:
    """The likelihood one target calls for: 'none' for a derived (smoothed) series or a noise-free curve,
    'stated' for a reconstruction's stated numbers, else its dataset's [noise] kind."""
    if target.derivation:
        return "none"
    return "stated" if target.observable == "stated" else target.dataset.noise_kind


def _likelihood(targets) -> str:
    """'none' if any target has no likelihood, else the targets' kind ('mixed' if they differ)."""
    kinds = {noise_kind(t) for t in targets}
    if "none" in kinds:
        return "none"
    return kinds.pop() if len(kinds) == 1 else "mixed"


LIKELIHOOD_REASON = {
    "known": "[noise] kind = known: sigma is measured, so the Gaussian likelihood uses it as given "
             "(AIC = chi2 + 2k + sum ln(2 pi sigma^2)); error bars are not rescaled",
    "estimated": "sigma estimated from the data without any law (io/noise.py), the same for every law: the "
                 "likelihood uses it as given, and the goodness of fit is an F test carrying the estimate's "
                 "degrees of freedom",
    "mixed": "the datasets differ: measured sigma where known, estimated from the data elsewhere",
    "stated": "[noise] kind = none, a noise-free reconstruction: laws are compared on the numbers it was drawn "
              "through ([stated]), the chi-square against their stated precision (one unit of the last digit; the "
              "framing interval for a time); the dense curve is for figures only",
    "none": "no valid likelihood: a derived series (omega smoothed from theta, correlated points) or a "
            "noise-free reconstruction",
}


def neg2loglik(chisqr: float, n: int, sigma: np.ndarray, kind: str) -> float:
    """-2 ln L of one dataset [constant included]: chi2 + C, C = sum ln(2 pi sigma_i^2), with sigma measured
    ('known') or estimated from the data alone ('estimated': one plug-in value for every law); nan for 'none'."""
    if kind not in AS_GIVEN:
        return math.nan
    return chisqr + float(np.sum(np.log(2 * math.pi * np.asarray(sigma, dtype=float) ** 2)))


def _si_result(best, slots):
    """A copy of lmfit's MinimizerResult in SI: the optimizer works on parameters divided by their
    typical size; values, bounds, errors, start values and the covariance are multiplied back."""
    if best is None:
        return None
    import copy

    scale = {s.pname: s.scale for s in slots}
    r = copy.copy(best)
    r.params = best.params.copy()
    for name, p in r.params.items():
        f = scale[name]
        p.set(min=p.min * f, max=p.max * f)  # bounds first: a value is clipped into them
        p.set(value=p.value * f)
        p.init_value = None if p.init_value is None else p.init_value * f
        p.stderr = None if p.stderr is None else p.stderr * f
    if getattr(best, "covar", None) is not None:
        d = np.array([scale[n] for n in best.var_names])
        r.covar = best.covar * np.outer(d, d)
    r.init_vals = [v * scale[n] for v, n in zip(best.init_vals, best.var_names)]
    r.init_values = {n: v * scale[n] for n, v in best.init_values.items()}
    return r


def _stats(n, k, k_free, chisqr, per) -> Stats:
    """Information criteria from the likelihood the datasets' noise calls for (module docstring):
    AIC = -2 ln L + 2 k, AICc = AIC + 2k(k+1)/(n-k-1), BIC = -2 ln L + k ln n (sigma measured or
    estimated without a law: no parameter of the fit). NaN without a valid likelihood ('none')."""
    single = len(per) == 1
    kind = _likelihood([d.target for d in per])
    base = dict(n_points=n, n_params=k, n_free=k_free, chisqr=chisqr, redchi=chisqr / (n - k) if n > k else math.inf,
                rss=per[0].rss if single else math.nan, rmse=per[0].rmse if single else math.nan,
                likelihood=kind, likelihood_reason=LIKELIHOOD_REASON[kind])
    if kind == "none":
        return Stats(aic=math.nan, aicc=math.nan, bic=math.nan, **base)
    ll, kk = 0.0, k
    for d in per:
        ll += neg2loglik(d.chisqr, d.target.y.size, d.target.sigma, noise_kind(d.target))
    aic = ll + 2 * kk
    aicc = aic + (2 * kk * (kk + 1) / (n - kk - 1) if n - kk - 1 > 0 else math.inf)
    return Stats(aic=aic, aicc=aicc, bic=ll + kk * math.log(n), neg2loglik=ll, k_lik=kk, **base)


def _series_notes(law, per) -> list[str]:
    from ...solve.solvers.series import B_ACCURATE

    notes = []
    for d in per:
        if d.solver == "series":
            form = law.form(d.params)
            s = d.scene
            b = form.k * s.area.peak * s.area.contact_time / (s.mass * math.pi)
            if b > B_ACCURATE:
                notes.append(f"series on '{d.name}' at b = {b:.3g}: the first-order expansion (eq 7) is accurate "
                             f"only for b << 1 (below about {B_ACCURATE})")
            if b > 0.5:
                t_rev = math.acos(-(1 - b) / b) * s.area.contact_time / math.pi
                notes.append(f"series on '{d.name}': with b = {b:.3g} > 0.5 the truncated slip u0 (1 - b + b cos phi t) "
                             f"changes sign at t = {t_rev * 1e6:.0f} us (u(t_c) = u0 (1 - 2b) < 0), so the series "
                             "force reverses there, while the exact slip u0 exp(-b (1 - cos phi t)) never does. The series "
                             "spin falls exactly while its slip is negative: its rise-then-fall comes from the "
                             "truncation, not from the law")
    return notes


def _param_results(slots, best, targets, structure, jac) -> dict[str, ParamResult]:
    """ParamResults in SI: lmfit's error bars; none where the data cannot give one (ratio-only,
    no effect); the Jacobian's over the identifiable directions where lmfit gave none or where a
    degeneracy makes its covariance unreliable. Ratio-only pairs add their ratio ('derived')."""
    out = {}
    degenerate = bool(structure["ratios"] or structure["no_effect"])  # lmfit's covariance is then unreliable
    for s in slots:
        p = best[s.pname]
        err = p.stderr * s.scale if (s.vary and p.stderr is not None and np.isfinite(p.stderr)) else None
        side = structure.get("sides", {}).get(s.display, "")
        if side or s.display in structure["no_effect"] or (s.vary and in_ratio(s, structure)):
            err = None  # at a bound, without effect, or only a ratio determined: no error is defined
        elif s.vary and (err is None or degenerate):
            err = jac["errors"].get(s.display)
        out[s.display] = ParamResult(s.display, s.key, s.kind, p.value * s.scale, err, s.unit, s.vary, s.value,
                                     s.lower, s.upper, tuple(targets[i].name for i in s.targets), s.fixed_by, s.shown,
                                     side)
    for name, (value, err, unit, slot) in jac["derived"].items():
        out[name] = ParamResult(name, name.split("[")[0], "derived", value, err, unit, False, value, 0.0, math.inf,
                                tuple(targets[i].name for i in slot.targets),
                                "derived: the combination the data determine")
    return out


