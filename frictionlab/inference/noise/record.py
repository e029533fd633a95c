"""A record's noise chosen by the data: one ``arp`` model and one innovation level per sampling-rate group.

Samples are grouped by rate as for AR(1) noise (``ar1.rate_groups``); each contiguous run of a group is whitened
on its own (the filter restarts at a change of rate). ``estimate`` chooses every group's model from a fit's
residuals (the first candidate whose whitened residuals are white, else an AR(1) working model) and profiles its
innovation standard deviation (the maximum-likelihood value, the root mean square of
the whitened residuals); the fit then weights by it, and the two alternate (feasible GLS, ``velstep``).
"""
from __future__ import annotations

import math

import attrs
import numpy as np

from . import ar1
from . import arp


@attrs.define
class RecordNoise:
    """Per rate group: the model, its innovation standard deviation sigma_g; the runs of each group."""

    labels: np.ndarray  # rate group of each sample
    refs: np.ndarray  # median interval [s] of each group
    models: list  # arp.NoiseModel per group
    sigma_g: np.ndarray  # innovation standard deviation per group (the data's unit)
    runs: list = attrs.field(factory=list)  # (start, stop, group) of each contiguous run

    @classmethod
    def of(cls, t, sigma_start) -> "RecordNoise":
        """White noise at the level ``sigma_start`` (per sample) until ``estimate`` is called."""
        labels, refs = ar1.rate_groups(t)
        sig = np.broadcast_to(np.asarray(sigma_start, dtype=float), np.shape(t))
        sigma_g = np.array([float(np.median(sig[labels == g])) if np.any(labels == g) else 1.0
                            for g in range(refs.size)])
        cuts = np.nonzero(np.diff(labels))[0] + 1
        edges = np.concatenate([[0], cuts, [labels.size]])
        runs = [(int(a), int(b), int(labels[a])) for a, b in zip(edges[:-1], edges[1:]) if b > a]
        return cls(labels, refs, [arp.WHITE] * refs.size, sigma_g, runs)

    @property
    def sigma(self) -> np.ndarray:
        """Innovation standard deviation of each sample."""
        return self.sigma_g[self.labels]

    @property
    def n_coef(self) -> int:
        """Noise coefficients fitted over the groups (AR orders, ARMA's two), their levels not counted."""
        return sum(m.n_coef for m in self.models)

    def whiten(self, v, best: bool = False) -> np.ndarray:
        """v (samples, or samples x columns) whitened run by run with each group's model (innovation scale); with
        ``best``, a working model's stand-in (``arp.ar1_working``) in its place."""
        v = np.asarray(v, dtype=float)
        out = np.empty_like(v)
        for a, b, g in self.runs:
            m = self.models[g]
            out[a:b] = arp.whiten(v[a:b], m.best if best and m.best is not None else m)
        return out

    def log_det_terms(self) -> np.ndarray:
        """Each sample's part of ``log_det`` (nonzero at the start of a run only)."""
        out = np.zeros(self.labels.size)
        for a, b, g in self.runs:
            m = self.models[g]
            if m.kind == "ARMA(1,1)":
                out[a] = math.log(m.variance_ratio)
            elif m.kind == "AR":
                _, ratio = arp.startup(m)
                k = min(ratio.size, b - a)
                out[a:a + k] = np.log(ratio[:k])
        return out

    def log_det(self) -> float:
        """The whitening's term of -2 ln L over the runs."""
        return sum(arp.log_det(self.models[g], b - a) for a, b, g in self.runs)

    def whiteness(self, z, g: int, model=None) -> tuple[float, int]:
        """(p, lags) of the Ljung-Box test that z (residuals, every sample) whitened by ``model`` (default: group g's
        own; the filter restarts at each of the group's runs) are white over group g's samples: max(WHITE_LAGS,
        order + 10) lags, the model's coefficients taken from the degrees of freedom; p is NaN when too short."""
        from ..diagnostics.goodness import WHITE_LAGS, ljung_box

        m = self.models[g] if model is None else model
        pieces = [arp.whiten(z[a:b], m) for a, b, gg in self.runs if gg == g]
        lags = max(WHITE_LAGS, m.order + 10)
        return (ljung_box(np.concatenate(pieces), m.n_coef, lags) if pieces else math.nan), lags

    def estimate(self, residual, profile: bool = True) -> float:
        """Choose each group's model from ``residual`` (model - data): the first of ``arp.candidates`` whose whitened
        residuals pass the Ljung-Box test (``whiteness``) at FITS_LEVEL, Bonferroni over the groups; where none
        does, ``arp.ar1_working`` (kept for the rest of the fit). When ``profile``, set sigma_g to the root mean
        square of the whitened residual. Returns the largest relative change of a group's sigma_g."""
        from ..diagnostics.goodness import FITS_LEVEL

        r = np.asarray(residual, dtype=float)
        old = self.sigma_g.copy()
        level = FITS_LEVEL / max(1, self.refs.size)
        for g in range(self.refs.size):
            pieces = [r[a:b] for a, b, gg in self.runs if gg == g]
            x = np.concatenate(pieces) if pieces else np.zeros(0)
            x = x - x.mean() if x.size else x
            if self.models[g].robust:  # kept: only its coefficient follows the residuals
                self.models[g], _ = arp.ar1_working(x, self.models[g].robust, self.models[g].best)
                continue
            names, ps, first = [], [], None
            for m, _ in arp.candidates(x, 1.0 / self.refs[g]):
                first = first or m
                p, lags = self.whiteness(r, g, m)
                if not p < level:
                    self.models[g] = m
                    break
                names.append(m.name)
                ps.append(f"{p:.1g}" if p > 0 else "below 1e-300")
            else:
                verb = "leaves" if len(names) == 1 else "leave"
                listed = " and ".join([", ".join(names[:-1]), names[-1]] if len(names) > 1 else names)
                why = f"{listed} {verb} the residuals correlated (Ljung-Box p = {', '.join(ps)})"
                self.models[g], _ = arp.ar1_working(x, why, first)
        if profile:
            w = self.whiten(r)
            for g in range(self.refs.size):
                sel = self.labels == g
                ms = float(np.mean(w[sel] ** 2)) if sel.any() else math.nan
                if math.isfinite(ms) and ms > 0:
                    self.sigma_g[g] = math.sqrt(ms)
        return float(np.max(np.abs(self.sigma_g / old - 1.0))) if old.size else 0.0

    def ar1_form(self):
        """Where every group's model is white or AR(1): (1 / marginal sigma, phi, 1 / sqrt(1 - phi^2)) per sample,
        phi 0 at the start of each run, the weights with which ``velstep.kernel.basis_sums`` whitens exactly as
        ``whiten`` does; None otherwise."""
        if any(m.kind == "ARMA(1,1)" or m.order > 1 for m in self.models):
            return None
        phi_g = np.array([m.ar[0] if m.order else 0.0 for m in self.models])
        phi = phi_g[self.labels]
        inv = np.sqrt(1.0 - phi * phi) / self.sigma
        phi = phi.copy()
        phi[[a for a, _, _ in self.runs]] = 0.0
        return inv, phi, 1.0 / np.sqrt(1.0 - phi * phi)

    @property
    def robust(self) -> bool:
        """Whether some group's noise no candidate model whitens (its AR(1) a working model: sandwich errors)."""
        return any(m.robust for m in self.models)

    def describe(self) -> list[tuple[str, str]]:
        """(rate label, model name) per group: ('100 Hz', 'AR(6)')."""
        return [(f"{1 / r:.3g} Hz", m.name + (f" working model: {m.robust}; Newey-West sandwich error bars, the "
                                              f"law-fit bands under {m.best.name}" if m.robust else
                                              " (AR order at its cap)" if m.capped else ""))
                for r, m in zip(self.refs, self.models)]

    def draw(self, rng) -> np.ndarray:
        """One draw of the noise: each run of each group from its model at its innovation level (stationary)."""
        out = np.empty(self.labels.size)
        for a, b, g in self.runs:
            out[a:b] = arp.draw(rng, self.models[g], b - a, float(self.sigma_g[g]), burn=500)
        return out


def noise_drawer(dataset, y, model, sigma):
    """A function rng -> one draw of noise for a parametric replicate of data y around a fit's ``model`` of them:
    where ``dataset`` declares ``correlation = "arp"``, from the noise model a fit of these data chooses (each
    group's model and level from the residual y - model); otherwise ``ar1.noise_drawer``."""
    if getattr(dataset, "noise_correlation", "none") != "arp" or "t" not in dataset.columns:
        return ar1.noise_drawer(dataset, y, model, sigma)
    t = np.asarray(dataset.columns["t"], dtype=float)
    start = np.broadcast_to(np.asarray(sigma if sigma is not None else 1.0, dtype=float), t.shape)
    rec = RecordNoise.of(t, start)
    rec.estimate(np.asarray(model) - np.asarray(y))
    return rec.draw

