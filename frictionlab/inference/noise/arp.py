"""Noise chosen by the data: an AR(p) model (order by BIC up to a cap that suits the sampling rate), or ARMA(1,1)
where the AR order runs to its cap, for the residuals of one sampling-rate group of a record.

* Coefficients by Burg's method (reflection coefficients k_1..k_p; the recursion keeps the model stationary), the
  order p = 0..cap minimizing BIC = n ln E_p + p ln n (E_p: Burg's prediction-error power). The cap grows with
  the rate (``order_cap``: tens of lags at 1 kHz, a few at 10 Hz) and stays below n / 20.
* Where BIC's order is the cap (the AR order runs away), ARMA(1,1) (x_t = phi x_{t-1} + e_t + theta e_{t-1}),
  fitted by conditional least squares, takes its place when its BIC is lower than the capped AR's.
* Candidates (``candidates``): BIC's choice, then ARMA(1,1) or the capped AR(p) (whichever BIC did not choose),
  then AR at the cap; the record's model is the first whose whitened residuals pass the Ljung-Box test
  (``noise.record``). Where none does, AR(1) (``ar1_working``) is a working model only: the fit is
  AR(1)-prewhitened and its error bars are the Newey-West sandwich (``velstep.result``).
* Whitening (``whiten``): the exact innovations of a stationary AR(p) (Durbin-Levinson: sample i < p is
  predicted by the order-i predictor and scaled by the ratio of its prediction variance to the innovation
  variance), then ``scipy.signal.lfilter`` with the AR polynomial; ARMA(1,1) is filtered by (1 - phi L) /
  (1 + theta L) with its first sample at the marginal variance (conditional likelihood). The result has the
  innovation variance at every sample; ``log_det`` is the whitening's term of -2 ln L, so that with sigma the
  innovation standard deviation -2 ln L = sum (w / sigma)^2 + n ln(2 pi sigma^2) + log_det.
"""
from __future__ import annotations

import math

import attrs
import numpy as np

#: The order cap at a sampling rate f [Hz]: 2 sqrt(f) lags, at least MIN_CAP and at most MAX_CAP (6 at 10 Hz, 20
#: at 100 Hz, 63 at 1 kHz), and below n / SAMPLES_PER_LAG samples of the group.
MIN_CAP, MAX_CAP, SAMPLES_PER_LAG = 4, 64, 20


@attrs.frozen
class NoiseModel:
    """A fitted stationary noise model of one rate group: 'white', 'AR' (order p) or 'ARMA(1,1)'."""

    kind: str
    ar: tuple = ()  # phi_1..phi_p of x_t = sum phi_j x_{t-j} + e_t (+ theta e_{t-1})
    ma: float = 0.0  # theta of ARMA(1,1)
    refl: tuple = ()  # reflection coefficients k_1..k_p (AR)
    cap: int = 0  # the largest order BIC could choose
    capped: bool = False  # BIC's AR order was the cap
    robust: str = ""  # why this AR(1) is a working model only (no candidate whitened the residuals), '' otherwise
    best: "NoiseModel | None" = None  # a working model's stand-in: the data's best candidate (``candidates``)

    @property
    def order(self) -> int:
        return len(self.ar)

    @property
    def n_coef(self) -> int:
        """Coefficients fitted: p, or 2 for ARMA(1,1)."""
        return self.order + (1 if self.kind == "ARMA(1,1)" else 0)

    @property
    def name(self) -> str:
        """'white', 'AR(6)', 'ARMA(1,1)'."""
        return self.kind if self.kind != "AR" else f"AR({self.order})"

    @property
    def variance_ratio(self) -> float:
        """Marginal variance over innovation variance."""
        if self.kind == "ARMA(1,1)":
            phi, th = self.ar[0], self.ma
            return (1 + 2 * phi * th + th * th) / (1 - phi * phi)
        return float(np.prod(1.0 / (1.0 - np.asarray(self.refl) ** 2))) if self.refl else 1.0


WHITE = NoiseModel("white")


def order_cap(rate: float, n: int) -> int:
    """The largest AR order BIC chooses from at sampling rate ``rate`` [Hz] with n samples (module docstring)."""
    cap = int(np.clip(round(2 * math.sqrt(max(rate, 0.0))), MIN_CAP, MAX_CAP))
    return max(0, min(cap, n // SAMPLES_PER_LAG))


def burg(x, pmax: int) -> tuple[list[np.ndarray], np.ndarray, np.ndarray]:
    """Burg's recursion on x (its mean kept: residuals of a fit with a constant have mean about 0): (AR coefficients
    of each order 0..pmax, reflection coefficients k_1..k_pmax, prediction-error power E_0..E_pmax)."""
    x = np.asarray(x, dtype=float)
    f, b = x[1:].copy(), x[:-1].copy()
    a = np.zeros(0)
    coefs, ks = [a], []
    E = [float(x @ x) / x.size]
    for _ in range(pmax):
        den = float(f @ f + b @ b)
        k = 2.0 * float(f @ b) / den if den > 0 else 0.0
        k = min(max(k, -0.99999), 0.99999)
        a = np.concatenate([a - k * a[::-1], [k]])
        ks.append(k)
        E.append(E[-1] * (1 - k * k))
        f, b = f[1:] - k * b[1:], b[:-1] - k * f[:-1]
        coefs.append(a)
    return coefs, np.array(ks), np.array(E)


def candidates(x, rate: float):
    """The noise models of residuals x of one group sampled at ``rate`` [Hz], best first, each with its innovation
    variance (a generator: a later candidate is fitted only when asked for): BIC's choice (module docstring); then
    ARMA(1,1) or the capped AR(p), whichever BIC did not choose; then AR at the cap."""
    x = np.asarray(x, dtype=float)
    n = x.size
    cap = order_cap(rate, n)
    if n < 10:
        yield WHITE, float(x @ x) / max(n, 1)
        return
    coefs, ks, E = burg(x, cap)
    E = np.maximum(E, 1e-300)
    bic = n * np.log(E) + np.arange(cap + 1) * math.log(n)
    p = int(np.argmin(bic))

    def ar(q):
        return (NoiseModel("AR", tuple(coefs[q]), 0.0, tuple(ks[:q]), cap, q == cap) if q else
                attrs.evolve(WHITE, cap=cap)), float(E[q])

    def arma():
        fitted = _arma11(x)
        return None if fitted is None else (NoiseModel("ARMA(1,1)", (fitted[0][0],), fitted[0][1], (), cap, p == cap),
                                            fitted[1])

    if p == cap and p:
        other = arma()
        if other is not None and n * math.log(other[1]) + 2 * math.log(n) < bic[p]:
            yield other
            yield ar(p)
            return
        yield ar(p)
        if other is not None:
            yield other
        return
    yield ar(p)
    other = arma()
    if other is not None:
        yield other
    if cap > p:
        yield ar(cap)


def select(x, rate: float) -> tuple[NoiseModel, float]:
    """The noise model of residuals x of one group sampled at ``rate`` [Hz] (the first of ``candidates``) and its
    innovation variance."""
    return next(candidates(x, rate))


def ar1_working(x, why: str, best: NoiseModel) -> tuple[NoiseModel, float]:
    """AR(1) of x by Burg's method, marked as the working model of noise that no candidate whitens (``why``;
    ``best``: the data's best candidate, which the law-fit test keeps)."""
    coefs, ks, E = burg(np.asarray(x, dtype=float), 1)
    return NoiseModel("AR", tuple(coefs[1]), 0.0, tuple(ks), robust=why, best=best), float(max(E[1], 1e-300))


def _arma11(x) -> tuple[tuple[float, float], float] | None:
    """(phi, theta) and innovation variance of ARMA(1,1) by conditional least squares on x, None if it fails."""
    from scipy.optimize import minimize
    from scipy.signal import lfilter

    def sse(p):
        phi, th = np.clip(np.tanh(p), -0.99999, 0.99999)  # inside the stationary and invertible region (tanh rounds to 1)
        e = lfilter([1.0, -phi], [1.0, th], x)
        return float(e[1:] @ e[1:])

    r1 = float(x[1:] @ x[:-1]) / max(float(x @ x), 1e-300)
    best = None
    for start in ((np.arctanh(min(max(r1, -0.9), 0.9)), 0.0), (np.arctanh(0.95), -0.5), (np.arctanh(0.99), -0.9)):
        r = minimize(sse, np.array(start, dtype=float), method="Nelder-Mead",
                     options={"xatol": 1e-6, "fatol": 1e-10 * max(float(x @ x), 1e-300), "maxiter": 400})
        if best is None or r.fun < best.fun:
            best = r
    if best is None or not np.isfinite(best.fun):
        return None
    phi, th = np.clip(np.tanh(best.x), -0.99999, 0.99999)  # as the AR reflections: never a unit root
    return (float(phi), float(th)), best.fun / (x.size - 1)


def startup(model: NoiseModel) -> tuple[list[np.ndarray], np.ndarray]:
    """The order-i predictors (i < p) of a stationary AR(p) from its reflection coefficients, and each start-up
    sample's prediction variance over the innovation variance."""
    preds, a = [], np.zeros(0)
    for k in model.refl:
        preds.append(a)
        a = np.concatenate([a - k * a[::-1], [k]])
    ks = np.asarray(model.refl)
    # variance of the order-i prediction error / innovation variance = prod_{j > i} 1 / (1 - k_j^2)
    ratio = np.array([float(np.prod(1.0 / (1.0 - ks[i:] ** 2))) for i in range(ks.size)])
    return preds, ratio


def whiten(v, model: NoiseModel) -> np.ndarray:
    """The innovations of v (a vector, or samples x columns, filtered along the first axis) under ``model``,
    scaled to the innovation variance at every sample (module docstring)."""
    from scipy.signal import lfilter

    v = np.asarray(v, dtype=float)
    if model.kind == "white" or not v.shape[0]:
        return v.copy()
    if model.kind == "ARMA(1,1)":
        phi = model.ar[0]
        out = lfilter([1.0, -phi], [1.0, model.ma], v, axis=0)
        out[0] = v[0] / math.sqrt(model.variance_ratio)
        return out
    p = model.order
    out = lfilter(np.concatenate([[1.0], -np.asarray(model.ar)]), [1.0], v, axis=0)
    preds, ratio = startup(model)
    for i in range(min(p, v.shape[0])):
        a = preds[i]
        e = v[i] - (np.tensordot(a, v[i - 1::-1][:i], axes=(0, 0)) if i else 0.0)
        out[i] = e / math.sqrt(ratio[i])
    return out


def log_det(model: NoiseModel, n: int) -> float:
    """The whitening's term of -2 ln L for n samples: sum of ln(prediction variance / innovation variance)."""
    if model.kind == "white" or n == 0:
        return 0.0
    if model.kind == "ARMA(1,1)":
        return math.log(model.variance_ratio)
    _, ratio = startup(model)
    return float(np.sum(np.log(ratio[:n])))


def draw(rng, model: NoiseModel, n: int, sigma: float = 1.0, burn: int = 2000) -> np.ndarray:
    """n samples of the model's stationary noise of innovation standard deviation sigma (a burn-in of ``burn``
    samples dropped)."""
    from scipy.signal import lfilter

    e = rng.standard_normal(n + burn) * sigma
    if model.kind == "white":
        return e[burn:]
    ma = [1.0, model.ma] if model.kind == "ARMA(1,1)" else [1.0]
    return lfilter(ma, np.concatenate([[1.0], -np.asarray(model.ar)]), e)[burn:]


def from_coefficients(ar=(), ma: float = 0.0) -> NoiseModel:
    """A model of given coefficients (reflection coefficients by the step-down recursion): for synthetic noise."""
    ar = tuple(float(c) for c in ar)
    if ma:
        return NoiseModel("ARMA(1,1)", ar, float(ma))
    a, ks = np.asarray(ar, dtype=float), []
    while a.size:
        k = a[-1]
        if not abs(k) < 1:
            raise ValueError(f"AR coefficients {ar}: not stationary")
        ks.append(k)
        a = (a[:-1] + k * a[:-1][::-1]) / (1 - k * k)
    return NoiseModel("AR", ar, 0.0, tuple(ks[::-1])) if ar else WHITE
