"""Does the law fit? Structure a law leaves after a step that the noise model cannot explain, judged against the
record's own steady state (a separate question from whether the noise model is adequate: ``goodness.ljung_box``
on the whitened residuals).

The whitened, normalized residuals w (independent N(0, 1) under the noise model) are cut into bands of slip after
each step: 0-1, 1-3, 3-10 and 10-30 Dc (a band with fewer than MIN_BAND samples joins the next). The record's own
steady state is the reference: the samples before the first step and those beyond REF_DC Dc after a step (the
law's new steady state), of the band's sampling rate where there are enough. A law that misses the transient
leaves, in some band, a mean (the low-frequency part of the misfit) or a mean square beyond the steady state's.
Each band of n_b samples is tested twice:

* its mean: T = n_b mean(w)^2 against the same statistic of the reference cut into m stretches of n_b samples:
  T / mean(T_ref) against F(1, m), so that slow noise the model misses, present in the steady state too, raises
  the reference with it; with fewer than MIN_REFS such stretches, against chi-square(1) (the noise model's own
  null);
* its mean square against the reference's: mean(w_b^2) / mean(w_ref^2) against F(n_b, n_ref) (against
  chi-square(n_b) / n_b without a reference).

The p-values are Bonferroni-adjusted over every test made; the law fails when the smallest is below the level,
and the band that says so is named.
"""
from __future__ import annotations

import math

import attrs
import numpy as np

#: Samples a band needs (fewer: it joins the next); steady-state bands the reference needs.
MIN_BAND, MIN_REFS = 20, 3
#: Band edges in slip after the step, in units of Dc; beyond REF_DC Dc the record is at its new steady state.
REF_DC = 30.0
EDGES_DC = (0.0, 1.0, 3.0, 10.0, REF_DC)


@attrs.frozen
class BandTest:
    """The law-fit test of one record: the adjusted p, the band and statistic that decide it, every band's p."""

    p: float  # Bonferroni-adjusted over the bands' tests; NaN when no band could be tested
    band: str  # '3-10 Dc after step 1' (the smallest p), '' without a test
    what: str  # 'mean' | 'mean square'
    bands: tuple = ()  # (band, p of its mean, p of its mean square), unadjusted
    reference: str = ""  # what the steady state gave: 'm steady-state bands' or why none

    def text(self, level: float) -> str:
        if not math.isfinite(self.p):
            return "no band after a step could be tested"
        verdict = "misses" if self.p < level else "no structure beyond the noise"
        return f"{verdict} ({self.what} {self.band}, p = {self.p:.2g} Bonferroni over {2 * len(self.bands)} tests)"


def band_test(w, t, x, step_times, Dc: float, labels=None) -> BandTest:
    """The test (module docstring) of normalized whitened residuals w at times t [s] with load-point displacement
    x [um]; step_times [s] of the load's steps; Dc [um]; labels: each sample's sampling-rate group."""
    from scipy.special import chdtrc, fdtrc

    w = np.asarray(w, dtype=float)
    t = np.asarray(t, dtype=float)
    labels = np.zeros(t.size, dtype=int) if labels is None else np.asarray(labels)
    steps = [ts for ts in step_times if t[0] < ts < t[-1]]
    if not steps or not Dc > 0:
        return BandTest(math.nan, "", "", reference="no step inside the record")
    steady = t < steps[0]
    bounds = steps + [math.inf]
    after = []
    for j, ts in enumerate(steps):
        sel = np.nonzero((t >= ts) & (t < bounds[j + 1]))[0]
        slip = x[sel] - float(np.interp(ts, t, x))
        steady[sel[slip >= REF_DC * Dc]] = True
        after.append((j, sel, slip))
    rows, out = [], []
    for j, sel, slip in after:
        for lo, hi in _bands(slip / Dc):
            idx = sel[(slip >= lo * Dc) & (slip < hi * Dc)]
            nb = idx.size
            name = f"{lo:g}-{hi:g} Dc after step {j + 1}"
            wb = w[idx]
            same = steady & (labels == np.bincount(labels[idx]).argmax())
            ref_mask = same if np.count_nonzero(same) >= MIN_REFS * nb else steady
            chunks = _stretches(w, ref_mask, nb)
            T = nb * float(np.mean(wb)) ** 2
            if len(chunks) >= MIN_REFS:
                Tref = float(np.mean([nb * float(np.mean(c)) ** 2 for c in chunks]))
                p_mean = float(fdtrc(1, len(chunks), T / Tref)) if Tref > 0 else math.nan
            else:
                p_mean = float(chdtrc(1, T))
            ref = w[ref_mask]
            ms = float(np.mean(wb ** 2))
            if ref.size >= MIN_BAND:
                p_ms = float(fdtrc(nb, ref.size, ms / float(np.mean(ref ** 2))))
            else:
                p_ms = float(chdtrc(nb, nb * ms))
            rows.append((name, p_mean, p_ms))
            out += [(p_mean, name, "mean"), (p_ms, name, "mean square")]
    out = [o for o in out if math.isfinite(o[0])]
    if not out:
        return BandTest(math.nan, "", "", reference="no band long enough")
    p, band, what = min(out)
    n_ref = int(np.count_nonzero(steady))
    reference = (f"{n_ref} steady-state samples (before the step and beyond {REF_DC:g} Dc after it)"
                 if n_ref >= MIN_BAND else "no steady state in the record: the noise model's own null")
    return BandTest(min(1.0, p * len(out)), band, what, tuple(rows), reference)


def _stretches(w, mask, nb: int) -> list[np.ndarray]:
    """Non-overlapping stretches of nb consecutive samples of w where ``mask`` holds."""
    idx = np.nonzero(mask)[0]
    if not idx.size:
        return []
    cuts = np.nonzero(np.diff(idx) > 1)[0] + 1
    out = []
    for run in np.split(idx, cuts):
        for i in range(run.size // nb):
            out.append(w[run[i * nb:(i + 1) * nb]])
    return out


def _bands(slip_dc) -> list[tuple[float, float]]:
    """Band edges (in Dc) that each hold at least MIN_BAND samples of ``slip_dc`` (slip / Dc)."""
    out, lo = [], EDGES_DC[0]
    for hi in EDGES_DC[1:]:
        if np.count_nonzero((slip_dc >= lo) & (slip_dc < hi)) >= MIN_BAND:
            out.append((lo, hi))
            lo = hi
    return out
