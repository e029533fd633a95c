"""What a velocity-step fit says beside its table (``velstep_result.build``): the sign of a - b against the trend,
the noise model's adequacy, and what the data show that the law misses: a trend it was not given (a refit with one
lowers chi-square beyond the 0.1 % point of chi-square with one degree of freedom), a strengthening evolution
(b pressed to 0: a refit that lets b go below 0), and residual structure after a step: under AR(1) noise, runs of
same-sign mean residual in windows of slip; under the data's AR(p) model, the band of slip after the step where
the whitened residuals leave structure the noise model cannot explain (``noise.misfit``).
"""
from __future__ import annotations

import math

import attrs
import numpy as np

from .params import AB_SCALE, with_value
from .table import StepReport, StepRow

#: A parameter within this distance of a bound (in its optimizer coordinate, ``velstep.params``: a / 0.01, b / 0.01
#: or Nagata's softplus of b, ln Dc, ln k; relative for the last two) is at the bound.
AT_BOUND = 1e-3
#: Residual windows after a step beyond this many standard errors count as structure the law misses.
MISSING_Z = 4.0
CHI2_1_999 = 10.828  # the 0.1 % point of chi-square with one degree of freedom
REFIT_EVALS = 40  # evaluations on every sample of a diagnostic refit (after it converged on the subsample)


def report(problem, x, v, pieces, quantities, at_bound, goods) -> StepReport:
    """The StepReport: the table, the sign of a - b against the trend, bounds, the noise and what the law misses."""
    rows, sign, noise = [], [], []
    ab = v["a"] - v["b"]
    for s, pc, g in zip(problem.series, pieces, goods):
        V = s.load.velocities
        steps = tuple((float(V[i]), float(V[i + 1])) for i in range(V.size - 1))
        phi = tuple((f"{1 / r:.3g} Hz", float(p)) for r, p in zip(s.refs, s.phi_groups)) if s.ar1 else ()
        rows.append(StepRow(s.target.name, problem.law.name, quantities[s.target.name], phi, steps, g.fits, g.text,
                            tuple(s.noise.describe()) if s.arp else (), g.whiteness_text if s.arp else ""))
        if s.arp and g.noise_ok is False:
            noise.append(f"{s.target.name}: the noise model ({', '.join(m for _, m in s.noise.describe())}) does not "
                         f"whiten the residuals ({g.whiteness_text}): slow noise it cannot describe, a statement "
                         "about the noise model, not the law")
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
    below = attrs.evolve(p, lower=-p.upper, transform="lin", scale=AB_SCALE)  # b / 0.01 (a softplus stays > 0)
    try:
        problem.params[ib] = below
        problem._cache = None
        tried = [problem.local(with_value(x0, ib, below.to_x(p.from_x(x0[ib]))), problem.free, search=True)
                 for x0 in starts]
        tried = [t for t in tried if t[2]]  # on the subsample; the best one then on every sample
        if tried:
            xr, cost, ok = problem.local(min(tried, key=lambda t: t[1])[0], problem.free, max_nfev=REFIT_EVALS)
            best = (problem.values(xr), cost) if ok else None
    finally:
        problem.params[ib] = p
        problem._cache = None
    if best is None:
        return ""
    v, cost = best
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
            out += _bands(s, g) if s.arp else _structure(s, pc, v)
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


def _bands(s, g) -> list[str]:
    """The band after a step where the law leaves structure the data's noise model cannot explain."""
    return [f"{s.target.name}: structure the law leaves after the step, beyond the noise: the whitened residuals' "
            f"{g.band_what} over {g.band} (p = {g.band_p:.2g}, against the record's steady state)"]
