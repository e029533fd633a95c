"""First-order autoregressive (AR(1)) noise: the noise model of a dataset with ``[noise] correlation = "ar1"``.

Laboratory records are sampled faster than their noise decorrelates (mains lines, servo oscillation): the
residuals of a fit that describes the data are correlated from one sample to the next. The model here:

* Samples are grouped by sampling rate: intervals within a factor RATE_GAP of one another form one group (a
  record logged at 10 Hz and then at 100 Hz has two). Each group g has its own coefficient phi_g, per its median
  interval dt_g, and its own marginal noise level sigma_g (the two rates of one record are often filtered
  differently). Within a group the noise is an Ornstein-Uhlenbeck process sampled at the record's times:
  e_i = phi_i e_{i-1} + sqrt(1 - phi_i^2) sigma_g eps_i with phi_i = phi_g^(dt_i / dt_g), so jittered
  intervals are handled exactly; the first sample of a group's run (after a change of rate) has phi_i = 0.
* Prewhitening: w_i = (z_i - phi_i z_{i-1}) / sqrt(1 - phi_i^2) with z = e / sigma. The w_i are independent
  N(0, 1) under the model, and -2 ln L = sum w_i^2 + sum ln(2 pi sigma_i^2) + sum ln(1 - phi_i^2) (the last sum
  is the log-determinant of the whitening). With every phi_i = 0 this is the independent Gaussian likelihood.
* phi_g is profiled: the exact maximum-likelihood value for given residuals (``estimate_phi``), alternated with
  the fit until it settles. sigma_g is estimated without any law, as for independent noise (``io.noise``):
  Gasser-Sroka-Jennen-Steinmetz differences of the prewhitened data (``noise_sigma``), whose noise is
  independent, so that estimate's degrees of freedom hold.

Goodness of fit, error bars and the information criteria are then those of independent noise, applied to the
prewhitened series; each phi_g counts as one parameter of the fit.
"""
from __future__ import annotations

import math

import attrs
import numpy as np

#: Sampling intervals within this factor of one another are one rate group.
RATE_GAP = 2.0
#: The range of phi searched by ``estimate_phi``.
PHI_RANGE = (-0.95, 0.999)


def rate_groups(t) -> tuple[np.ndarray, np.ndarray]:
    """(group label of each sample, median interval [s] of each group) from sample times t [s]; the first
    sample takes its successor's group."""
    t = np.asarray(t, dtype=float)
    if t.size < 2:
        return np.zeros(t.size, dtype=int), np.ones(1)
    dt = np.diff(t)
    order = np.sort(np.unique(np.round(np.log(dt), 6)))
    cuts = order[:-1][np.diff(order) > math.log(RATE_GAP)] if order.size > 1 else order[:0]
    label_dt = np.searchsorted(cuts, np.log(dt), side="left")
    labels = np.concatenate([[label_dt[0]], label_dt])
    refs = np.array([float(np.median(dt[label_dt == g])) for g in range(cuts.size + 1)])
    return labels, refs


def coefficients(t, labels, refs, phi) -> np.ndarray:
    """phi_i of each sample (0 for the first sample of a group's run) for group coefficients phi (per group)."""
    t = np.asarray(t, dtype=float)
    out = np.zeros(t.size)
    if t.size < 2:
        return out
    same = labels[1:] == labels[:-1]
    g = labels[1:]
    base = np.asarray(phi, dtype=float)[g]
    ratio = np.diff(t) / refs[g]
    out[1:] = np.where(same, np.sign(base) * np.abs(base) ** ratio, 0.0)
    return out


def whiten(v, phi_i) -> np.ndarray:
    """w_i = (v_i - phi_i v_{i-1}) / sqrt(1 - phi_i^2) along the first axis of v (a vector, or points x columns)."""
    v = np.asarray(v, dtype=float)
    if not np.any(phi_i):
        return v.copy()
    c = 1.0 / np.sqrt(1.0 - phi_i * phi_i)
    out = np.empty_like(v)
    out[0] = v[0]
    if v.ndim == 1:
        out[1:] = (v[1:] - phi_i[1:] * v[:-1]) * c[1:]
    else:
        out[1:] = (v[1:] - phi_i[1:, None] * v[:-1]) * c[1:, None]
    return out


def log_det(phi_i) -> float:
    """sum ln(1 - phi_i^2): the whitening's term of -2 ln L."""
    return float(np.sum(np.log1p(-np.asarray(phi_i) ** 2)))


def estimate_phi(e, t, labels, refs) -> np.ndarray:
    """Each group's maximum-likelihood phi for residuals e (its sigma profiled): the minimum over phi of
    n_g ln(mean w^2) + sum ln(1 - phi_i^2) over the group's samples."""
    from scipy.optimize import minimize_scalar

    e = np.asarray(e, dtype=float)
    t = np.asarray(t, dtype=float)
    phis = np.zeros(refs.size)
    for g in range(refs.size):
        idx = np.nonzero(labels == g)[0]
        if idx.size < 3:
            continue
        pair = idx[idx > 0]
        pair = pair[labels[pair - 1] == g]  # samples whose predecessor is of the same group
        if pair.size < 2:
            continue
        ratio = (t[pair] - t[pair - 1]) / refs[g]
        prev = e[pair - 1]
        cur = e[pair]
        starts = np.setdiff1d(idx, pair, assume_unique=True)
        ss_start = float(e[starts] @ e[starts])

        def objective(phi):
            p = np.sign(phi) * np.abs(phi) ** ratio
            w = (cur - p * prev) ** 2 / (1.0 - p * p)
            return idx.size * math.log((ss_start + float(np.sum(w))) / idx.size) + float(np.sum(np.log1p(-p * p)))

        r1 = float(prev @ cur) / max(float(prev @ prev), 1e-300)
        r = minimize_scalar(objective, bounds=PHI_RANGE, method="bounded", options={"xatol": 1e-6})
        phis[g] = r.x if objective(r.x) <= objective(float(np.clip(r1, *PHI_RANGE))) else float(np.clip(r1, *PHI_RANGE))
    return phis


def noise_sigma(t, y, phi_i, labels, refs) -> tuple[np.ndarray, list]:
    """(sigma of each sample, each group's ``io.noise.NoiseEstimate``): the GSJS estimate of the prewhitened data
    y of each rate group (its noise is independent), each run of a group on its own without its first sample
    (which is not prewhitened: it keeps the data's level). A group without an estimate takes the others' largest."""
    from ...io.noise import gsjs

    t = np.asarray(t, dtype=float)
    w = whiten(y, phi_i)
    run = np.cumsum(np.concatenate([[1], labels[1:] != labels[:-1]]))
    inner = np.concatenate([[False], labels[1:] == labels[:-1]])
    ests = []
    for g in range(refs.size):
        idx = np.nonzero((labels == g) & inner)[0]
        est = gsjs(t[idx], w[idx], run[idx])
        ests.append(None if est is None else attrs.evolve(est, rows=idx[est.rows]))  # rows of the whole series
    sig = [e.sigma if e is not None and e.sigma > 0 else math.nan for e in ests]
    fallback = np.nanmax(sig) if np.isfinite(sig).any() else math.nan
    sigma_g = np.array([s if math.isfinite(s) else fallback for s in sig])
    return sigma_g[labels], ests


def pooled_df(ests, labels) -> float:
    """Effective degrees of freedom of the groups' sigma estimates together (Satterthwaite, each group weighted
    by its number of samples): (sum n_g)^2 / sum (n_g^2 / nu_g)."""
    n = np.bincount(labels, minlength=len(ests)).astype(float)
    terms = [ng * ng / e.df for ng, e in zip(n, ests) if e is not None and e.df > 0]
    return float(n.sum() ** 2 / sum(terms)) if terms else math.inf


def draw(rng, sigma_i, phi_i) -> np.ndarray:
    """One draw of the noise: z_0 ~ N(0, 1), z_i = phi_i z_{i-1} + sqrt(1 - phi_i^2) eps_i, times sigma_i."""
    eps = rng.standard_normal(np.shape(sigma_i))
    if not np.any(phi_i):
        return eps * sigma_i
    return _recursion(eps, np.asarray(phi_i, dtype=float)) * sigma_i


def _recursion(eps, phi):
    from ...core.jit import jit

    global _recursion_compiled
    if _recursion_compiled is None:
        _recursion_compiled = jit(_recursion_py)
    return _recursion_compiled(eps, phi)


def _recursion_py(eps, phi):
    z = np.empty_like(eps)
    z[0] = eps[0]
    for i in range(1, eps.size):
        z[i] = phi[i] * z[i - 1] + math.sqrt(1.0 - phi[i] * phi[i]) * eps[i]
    return z


_recursion_compiled = None


def fitted_noise(t, y, residual) -> tuple[np.ndarray, np.ndarray]:
    """(sigma_i, phi_i) of the AR(1) model for data y whose fit left ``residual``: phi profiled from the residual,
    sigma from the prewhitened data (the model a fit uses; module docstring)."""
    labels, refs = rate_groups(t)
    phi_i = coefficients(t, labels, refs, estimate_phi(residual, t, labels, refs))
    sigma_i, _ = noise_sigma(t, y, phi_i, labels, refs)
    return sigma_i, phi_i


def noise_drawer(dataset, y, model, sigma):
    """A function rng -> one draw of noise for a parametric replicate of data y around a fit's ``model`` of them:
    Gaussian of ``sigma`` (the likelihood's, per sample or one value), or, where ``dataset`` declares
    ``correlation = "ar1"``, AR(1) noise of the model a fit of these data uses (``fitted_noise``)."""
    if getattr(dataset, "noise_correlation", "none") != "ar1" or "t" not in dataset.columns:
        shape = np.shape(y)
        return lambda rng: rng.standard_normal(shape) * sigma
    sigma_i, phi_i = fitted_noise(dataset.columns["t"], y, np.asarray(y) - model)
    return lambda rng: draw(rng, sigma_i, phi_i)
