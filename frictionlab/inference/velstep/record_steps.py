"""One parameter set across the steps of a record, and the record fitted as one history.

A raw experiment's steps (``io.velstep.analyse``: each step's window starting at a steady state the data show)
are fitted by the velocity-step fit (``velstep``) three ways, for each state law the fit serves:

* per step: a, b, Dc, the machine stiffness k, mu_ss and the trend of each window, its own;
* shared: a, b and Dc (and Nagata's c) one set for every step (k, mu_ss and the trend still each window's own:
  the stiffness the fit sees mixes the machine with the gouge layer, which compacts between steps), the transfer
  test of ``transfer.shared_fit`` (the impacts' one-parameter-set test): the likelihood-ratio statistic
  LR = -2 ln L_shared + 2 ln L_per-step, both under one noise model (``ar1_neg2ll``: each window's residuals
  as AR(1), phi and the innovation variance profiled: the conditional Gaussian likelihood), against
  chi-square with dk = 3 (steps - 1) degrees of freedom (4 (steps - 1) with Nagata's c), and delta-AIC =
  LR - 2 dk, delta-BIC = LR - dk ln n.
  One set describes the steps when p >= ALPHA. Where AR(1) does not whiten the residuals (a slow wander the
  law does not follow) the chi-square reference is approximate and the screen says so;
* whole record (optional): the load-point history of every step and hold driving one simulation from the
  record's first steady state (the joint dataset).

The field's question behind the test (Ruina 1983; Bhattacharya et al. 2015): the slip law answers steps up and
down of the same size symmetrically, the aging law does not; where one law's single set describes both
directions and the other's does not, the data side with the first.
"""
from __future__ import annotations

import math
from collections.abc import Sequence

import attrs
import numpy as np

from ..equivalence.transfer import ALPHA, SharedFit, shared_fit


def ar1_neg2ll(f) -> float:
    """-2 ln L of a fit's residuals, every dataset as AR(1) noise with phi and the innovation variance profiled
    (conditional on each dataset's first residual): sum over datasets of (n - 1) (ln(2 pi s2) + 1)."""
    total = 0.0
    for d in f.per_dataset:
        r = np.asarray(d.residual, dtype=float)
        r0, r1 = r[:-1], r[1:]
        phi = float(r0 @ r1 / (r0 @ r0)) if r0 @ r0 > 0 else 0.0
        e = r1 - phi * r0
        s2 = float(e @ e) / e.size
        total += e.size * (math.log(2 * math.pi * s2) + 1.0)
    return total


def state_laws(fitted_only: bool = False) -> list[str]:
    """The registered state laws of the quasi-static slider (``fitted_only``: those the velocity-step fit serves,
    aging, slip, PRZ and Nagata's)."""
    from ...physics.registry import available_laws
    from ...solve.quasistatic import FITTED, LAWS

    registered = set(available_laws())
    return [name for name in LAWS if name in registered and (name in FITTED or not fitted_only)]


@attrs.frozen
class LawSteps:
    """One law on one record's steps: the per-step fits (in step order), the shared test, the whole-record fit."""

    law: str
    steps: tuple  # FitResult per step window
    shared: SharedFit | None = None
    joint: object = None  # FitResult of the whole record, or None
    n_points: int = 0

    @property
    def ok(self) -> bool:
        return all(f.ok for f in self.steps) and self.shared is not None and self.shared.status == "ok"

    @property
    def delta_bic(self) -> float:
        """BIC_shared - BIC_per-step = LR - dk ln n (negative: the shared set is preferred)."""
        if not self.ok:
            return math.nan
        return self.shared.lr - self.shared.dk * math.log(self.n_points)

    @property
    def one_set(self) -> bool | None:
        """Whether one parameter set describes every step (p >= ALPHA); None when the test could not run."""
        return None if not self.ok else self.shared.p_value >= ALPHA

    def verdict(self) -> str:
        """One sentence: the answer of the test, with its numbers."""
        law = self.law.replace("rate-state-", "")
        if not all(f.ok for f in self.steps):
            bad = next(f for f in self.steps if not f.ok)
            return f"{law}: no test: the fit of {', '.join(bad.datasets)} {bad.status} ({bad.reason})"
        s = self.shared
        if s is None or s.status != "ok":
            return f"{law}: no test: {s.reason if s is not None else 'the shared fit was not run'}"
        shared = [p for p in self.steps[0].params.values() if p.kind == "law" and p.key != "mu0"]  # a, b, Dc (, c)
        full = sum(1 for p in shared if p.vary) * (len(self.steps) - 1)
        held = f", not {full}: a parameter at a bound is not counted" if 0 < s.dk < full else ""
        nums = (f"LR = {s.lr:.4g} on {s.dk} degrees of freedom{held}, p = {s.p_value:.2g}; delta-AIC = "
                f"{s.delta_aic:+.4g}, delta-BIC = {self.delta_bic:+.4g}")
        names = ", ".join(p.key for p in shared)
        if self.one_set:
            return f"{law}: one set of {names} describes every step ({nums})"
        return f"{law}: the steps ask for separate {names} ({nums})"


def fit_steps(law: str, datasets: Sequence, *, joint=None, timeout: float | None = None, fit_kw=None) -> LawSteps:
    """``law`` fitted to each step window of ``datasets`` (Dataset objects, in step order), the shared-set test
    across them, and (``joint``: the whole-record Dataset) the whole record as one history."""
    from ..fitting.fit import fit

    kw = dict(fit_kw or {})
    steps = tuple(fit(law, d, timeout=timeout, **kw) for d in datasets)
    n = sum(len(d) for d in datasets)
    shared = (shared_fit(steps, timeout=timeout, likelihood=ar1_neg2ll) if len(steps) > 1 and all(f.ok for f in steps)
              else None)
    whole = fit(law, joint, timeout=timeout, **kw) if joint is not None else None
    return LawSteps(law, steps, shared, whole, n)


def answer(results: Sequence[LawSteps], directions: Sequence[str]) -> str:
    """The first screen's answer to "does one parameter set describe the up and the down steps, for which law"."""
    kinds = sorted(set(directions) - {"hold"})
    what = "the up and the down steps" if kinds == ["down", "up"] else f"the {' and '.join(kinds)} steps"
    tested = [r for r in results if r.one_set is not None]
    if not tested:
        return f"Does one parameter set describe {what}? No law could be tested."
    yes = [r.law.replace("rate-state-", "") for r in tested if r.one_set]
    no = [r.law.replace("rate-state-", "") for r in tested if not r.one_set]
    best = min(tested, key=lambda r: r.shared.chi2_shared + 2 * r.shared.k_shared)
    closer = (f"; of the shared sets, {best.law.replace('rate-state-', '')}'s has the lowest AIC"
              if len(tested) > 1 else "")
    if yes and no:
        return (f"Does one parameter set describe {what}? Yes for {', '.join(yes)}, no for {', '.join(no)} (the "
                f"likelihood-ratio test at {ALPHA:g}){closer}.")
    if yes:
        return f"Does one parameter set describe {what}? Yes, for every law tested ({', '.join(yes)}){closer}."
    return (f"Does one parameter set describe {what}? No, for no law tested ({', '.join(no)}): the steps ask for "
            f"separate sets{closer}.")
