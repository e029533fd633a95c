"""One dataset of the velocity-step fit (``velstep``): its times, data, load history, load-point displacement, the
columns of its linear parameters (mu_ss, the trend) and its noise model.

Noise, as the dataset declares it (``[noise] correlation``):

* 'none': independent samples at the dataset's sigma (known or estimated);
* 'ar1': the AR(1) model of ``inference.ar1`` (phi profiled per rate group, sigma from the prewhitened data);
* 'arp': the model chosen by the data per rate group (``noise.record``: AR(p) by BIC up to a cap suited to the
  rate, ARMA(1,1) where the order runs to the cap), its innovation level profiled in the likelihood.
"""
from __future__ import annotations

import math

import numpy as np

from ...core.errors import FrictionLabError
from ...solve import quasistatic
from ...solve.quasistatic import UM, Load
from ..fitting.stats import noise_kind
from ..noise import ar1
from ..noise.record import RecordNoise

#: Samples per dataset the grid of starts is scored on (every sample when there are fewer).
SEARCH_POINTS = 1500
#: Samples kept whole after each step in the search's subsample.
SEARCH_DENSE = 200


class Series:
    """One dataset prepared for the fit: times, data, load history, load-point displacement, linear columns and
    the noise model (sigma and phi per sample, or the data's AR(p) model per rate group)."""

    def __init__(self, target, index: int, trend: bool, mu0: float | None):
        ds = target.dataset
        self.target, self.index = target, index
        self.t = np.asarray(target.t, dtype=float)
        self.y = np.asarray(target.y, dtype=float)
        self.load = Load.of(ds.scene.spring)
        self.x = ds.columns["x"] / UM if "x" in ds.columns else self.load.displacement(self.t)
        first = self.load.times[1] if self.load.times.size > 1 else 0.0
        self.x_ref = float(np.interp(first, self.t, self.x)) if "x" in ds.columns else float(
            self.load.displacement(first))
        self.trend, self.mu0 = trend, mu0
        self.L1 = math.log(self.load.V1 / quasistatic.V0_UM)
        cols = ([np.ones_like(self.t)] if mu0 is None else []) + ([self.x - self.x_ref] if trend else [])
        self.B = np.column_stack(cols) if cols else np.zeros((self.t.size, 0))
        self.kind = noise_kind(target)
        correlation = getattr(ds, "noise_correlation", "none")
        self.ar1 = correlation == "ar1"
        self.sigma = np.broadcast_to(np.asarray(target.sigma, dtype=float), self.y.shape).copy()
        self.phi = np.zeros(self.t.size)
        self.labels, self.refs = ar1.rate_groups(self.t)
        #: The data's AR(p) / ARMA(1,1) model per rate group ('arp'), None otherwise.
        self.noise = RecordNoise.of(self.t, self.sigma) if correlation == "arp" else None
        self.held = False  # the noise model held as given (``hold_noise``), not estimated with the fit
        self.phi_groups = np.zeros(self.refs.size)
        self.noise_ests: list = []
        self.search = _search_index(self.t, self.load.times)
        self.t_search = np.ascontiguousarray(self.t[self.search])
        self.no_phi = np.zeros(self.search.size)  # the search's subsample is fitted as white noise
        self._set_weights()
        self._set_projection()

    @property
    def n(self) -> int:
        return self.t.size

    def _set_weights(self):
        """What the compiled sums read of sigma and phi: 1 / sigma and the prewhitening gain 1 / sqrt(1 - phi^2); with
        the data's AR(p) model, its weights for the compiled pass where it is AR(1) or white (``ar1_form``), else
        None. Called wherever the noise changes."""
        self.inv_sigma = 1.0 / self.sigma
        self.gain = 1.0 / np.sqrt(1.0 - self.phi ** 2)
        self.inv_sigma_search = self.inv_sigma[self.search]
        self.ar1_weights = self.noise.ar1_form() if self.noise is not None else None

    def _set_projection(self):
        """The orthonormal columns of the (prewhitened) linear parameters, and the data less a first guess of their
        linear part (y_ref): the sums of ``velstep_kernel`` then add numbers of the size of the transient and the
        noise, not of mu itself, and lose no precision; the projection removes any such part exactly."""
        self.Q = _basis(self.white(self.B / self.sigma[:, None]))
        s = self.search
        self.Q_search = _basis(self.B[s] / self.sigma[s, None])
        self.y_ref = (self.y - self.B @ np.linalg.lstsq(self.B, self.y - (self.mu0 or 0.0), rcond=None)[0]
                      if self.B.shape[1] else self.y)
        self.y_ref_search = self.y_ref[s]

    @property
    def arp(self) -> bool:
        """Whether the noise model is the data's AR(p) choice."""
        return self.noise is not None

    @property
    def correlated(self) -> bool:
        """Whether a noise model is fitted with the law (AR(1) or the data's AR(p))."""
        return self.ar1 or self.arp

    @property
    def n_noise(self) -> int:
        """Noise parameters fitted with the law: phi per group (AR(1)); coefficients and level per group (AR(p))."""
        if self.arp:
            return self.noise.n_coef + (self.refs.size if self.kind == "estimated" else 0)
        return self.refs.size if self.ar1 else 0

    def white(self, v) -> np.ndarray:
        """v / sigma (samples, or samples x columns) whitened by the noise model (a copy where there is none)."""
        return self.noise.whiten(v) if self.arp else ar1.whiten(v, self.phi)

    def log_det(self) -> float:
        """The whitening's term of -2 ln L."""
        return self.noise.log_det() if self.arp else ar1.log_det(self.phi)

    def log_det_terms(self) -> np.ndarray:
        """Each sample's part of ``log_det``."""
        return self.noise.log_det_terms() if self.arp else np.log1p(-self.phi ** 2)

    def noise_state(self) -> dict | None:
        """The fitted noise model, to hold in a refit (``hold_noise``): None for independent noise."""
        if self.arp:
            return {"kind": "arp", "models": tuple(self.noise.models), "sigma_g": self.noise.sigma_g.copy()}
        if self.ar1:
            return {"kind": "ar1", "phi_groups": self.phi_groups.copy(), "sigma": self.sigma.copy()}
        return None

    def hold_noise(self, state: dict | None) -> None:
        """Hold the noise model ``state`` (``noise_state`` of a fit of the same dataset) instead of estimating one."""
        if state is None:
            return
        if state["kind"] == "arp":
            if self.noise is None:
                self.noise = RecordNoise.of(self.t, self.sigma)
            self.noise.models = list(state["models"])
            self.noise.sigma_g = np.asarray(state["sigma_g"], dtype=float).copy()
            self.sigma = self.noise.sigma
        else:
            self.ar1, self.noise = True, None
            self.phi_groups = np.asarray(state["phi_groups"], dtype=float).copy()
            self.phi = ar1.coefficients(self.t, self.labels, self.refs, self.phi_groups)
            self.sigma = np.asarray(state["sigma"], dtype=float).copy()
        self.held = True
        self._set_weights()
        self._set_projection()

    def set_noise(self, residual) -> float:
        """Profile phi from ``residual`` (model - data) and re-estimate sigma from the prewhitened data (estimated
        noise) or keep the declared one (known): the largest change of a group's phi. With the data's AR(p)
        model: choose each group's model and profile its innovation level (estimated noise; a declared sigma is
        used as declared, as the innovation level), the largest relative change of a level or 1 where a model
        changed."""
        if self.arp:
            before = [m.name for m in self.noise.models]
            change = self.noise.estimate(residual, profile=self.kind == "estimated")
            if self.kind == "estimated":
                self.sigma = self.noise.sigma
            self._set_weights()
            self._set_projection()
            return 1.0 if [m.name for m in self.noise.models] != before else change
        phi = ar1.estimate_phi(residual, self.t, self.labels, self.refs)
        change = float(np.max(np.abs(phi - self.phi_groups))) if phi.size else 0.0
        self.phi_groups = phi
        self.phi = ar1.coefficients(self.t, self.labels, self.refs, phi)
        if self.kind == "estimated":
            self.sigma, self.noise_ests = ar1.noise_sigma(self.t, self.y, self.phi, self.labels, self.refs)
            if not np.all(np.isfinite(self.sigma) & (self.sigma > 0)):
                raise FrictionLabError(f"dataset '{self.target.name}': the noise of the prewhitened data cannot be "
                                       "estimated")
        self._set_weights()
        self._set_projection()
        return change

    def whitened_sums(self, off: float, m, S):
        """``velstep_kernel.all_sums`` under the data's AR(p) model: the residual and the basis columns weighted,
        whitened by a linear filter (``noise.record``), and their sums (w'w, B'w, B'B, Q'w, Q'B)."""
        if self.ar1_weights is not None:  # AR(1) or white in every group: the compiled pass
            from .kernel import all_sums

            return all_sums(self.y_ref, off, m, S, *self.ar1_weights, self.Q)
        inv = self.inv_sigma
        Z = np.empty((self.n, 2 + S.shape[1]))  # the residual, then the basis (S[:, :4], 1, S[:, 4:]) / sigma
        Z[:, 0] = (off + m - self.y_ref) * inv
        Z[:, 1:5] = S[:, :4] * inv[:, None]
        Z[:, 5] = inv
        Z[:, 6:] = S[:, 4:] * inv[:, None]
        W = self.noise.whiten(Z)
        w, D = W[:, 0], W[:, 1:]
        return float(w @ w), D.T @ w, D.T @ D, self.Q.T @ w, self.Q.T @ D

    def offset(self, a: float, b: float) -> float:
        """The model's part fixed by a held mu0 (at V0): mu0 + (a - b) ln(V1 / V0); 0 when mu_ss is fitted."""
        return 0.0 if self.mu0 is None else self.mu0 + (a - b) * self.L1

    def linear(self, a: float, b: float, m: np.ndarray) -> np.ndarray:
        """The linear coefficients (mu_ss and/or trend) for the nonlinear solution m, whitened least squares."""
        if not self.B.shape[1]:
            return np.zeros(0)
        w = self.white((self.y - self.offset(a, b) - m) / self.sigma)
        Bw = self.white(self.B / self.sigma[:, None])
        return np.linalg.lstsq(Bw, w, rcond=None)[0]


def _basis(A) -> np.ndarray:
    """An orthonormal basis of A's columns (n x 0 for none)."""
    if not A.shape[1]:
        return A[:, :0]
    return np.linalg.qr(A)[0]


def _search_index(t, step_times) -> np.ndarray:
    """Indices of the search's subsample: every sample when few, else SEARCH_DENSE samples whole after each step
    and an even stride elsewhere (about SEARCH_POINTS in all)."""
    n = t.size
    if n <= SEARCH_POINTS:
        return np.arange(n)
    keep = np.zeros(n, dtype=bool)
    keep[:: max(1, n // SEARCH_POINTS)] = True
    for ts in step_times[1:]:
        i = int(np.searchsorted(t, ts))
        keep[i:i + SEARCH_DENSE] = True
    keep[-1] = True
    return np.nonzero(keep)[0]


