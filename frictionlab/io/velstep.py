"""Raw laboratory velocity-step records in, a spring-slider dataset (CSV + TOML) out.

The raw format is the one of the steadystate routine's sliced records (Giacomel et al., Geosphere
2024): a header line, then whitespace-separated rows of time [s], load-point displacement [um],
friction [-] and (effective) normal stress [MPa], one velocity step per file. The importer finds the
load-point velocities and the step time(s) from the displacement record (a piecewise straight-line
fit), estimates the machine stiffness from the spring's loading right after the first step (to be
fitted with ``--free spring.stiffness``), on request (``--detrend``) removes the slip trend of friction
measured before the step (its uncertainty is not carried into the fit: the default keeps the record as
measured), and keeps a subset of the samples: dense just after each step where friction
changes fast, sparser later. Samples are picked, not averaged, so the noise stays that of the record.
"""
from __future__ import annotations

import math
import re
from pathlib import Path

import attrs
import numpy as np

from ..core.errors import DatasetError
from ..core.files import MAX_CSV_BYTES, read_text
from ..core.names import check_name

#: Header names accepted for the four raw columns (case-insensitive; '_' or nothing between words).
RAW_HEADER = (r"time\(s\)", r"displ(acement)?\(microns\)", r"friction", r"(effective_?)?normal_?stress\(mpa\)")
#: Fewest samples a constant-velocity segment may hold.
MIN_SEGMENT = 20


@attrs.frozen(eq=False)
class RawRecord:
    """One raw record in SI units: time [s], displacement [m], friction [-], normal stress [Pa] (``stress``:
    what the file's header calls it: effective normal stress, or normal stress where it does not say)."""

    path: Path
    t: np.ndarray
    x: np.ndarray
    mu: np.ndarray
    sn: np.ndarray
    stress: str = "effective normal stress"


def read_raw(path) -> RawRecord:
    """Read a raw velocity-step record; one-line DatasetError naming the file and line on bad content."""
    path = Path(path)
    lines = read_text(path, MAX_CSV_BYTES).splitlines()
    rows = [(i + 1, line) for i, line in enumerate(lines) if line.strip()]
    if not rows:
        raise DatasetError(f"{path}: file is empty")
    header = rows[0][1].split()
    if len(header) != 4 or not all(re.fullmatch(p, h, re.IGNORECASE) for p, h in zip(RAW_HEADER, header)):
        raise DatasetError(f"{path}: line {rows[0][0]}: header {rows[0][1].strip()!r}; expected four columns: "
                           "Time(s) Displ(microns) Friction EffectiveNormalstress(MPa) (or NormalStress(MPa))")
    data = np.empty((len(rows) - 1, 4))
    for k, (no, line) in enumerate(rows[1:]):
        parts = line.replace(",", " ").split()
        try:
            values = [float(p) for p in parts]
        except ValueError:
            values = []
        if len(values) != 4 or not all(math.isfinite(v) for v in values):
            raise DatasetError(f"{path}: line {no}: expected four finite numbers, got {line.strip()[:60]!r}")
        data[k] = values
    if len(data) < 2 * MIN_SEGMENT:
        raise DatasetError(f"{path}: {len(data)} data rows; a velocity step needs at least {2 * MIN_SEGMENT}")
    t, x_um, mu, sn = data.T
    bad = np.nonzero(np.diff(t) <= 0)[0]
    if bad.size:
        raise DatasetError(f"{path}: line {rows[int(bad[0]) + 2][0]}: time does not increase")
    if np.any(sn <= 0):
        raise DatasetError(f"{path}: normal stress must be positive")
    stress = "effective normal stress" if "effective" in header[3].lower() else "normal stress"
    return RawRecord(path=path, t=t, x=x_um * 1e-6, mu=mu, sn=sn * 1e6, stress=stress)


def _line_fit_rss(t, x):
    """For every split index j, the residual sum of squares of straight lines through x[:j] and x[j:]."""
    n = len(t)

    def rss_prefix(tt, xx):
        k = np.arange(1, len(tt) + 1, dtype=float)
        st, sx = np.cumsum(tt), np.cumsum(xx)
        stt, sxx, stx = np.cumsum(tt * tt), np.cumsum(xx * xx), np.cumsum(tt * xx)
        var_t = stt - st**2 / k
        cov = stx - st * sx / k
        var_x = sxx - sx**2 / k
        with np.errstate(invalid="ignore", divide="ignore"):
            return var_x - np.where(var_t > 0, cov**2 / var_t, 0.0)

    head = rss_prefix(t, x)  # head[j-1]: rss of the first j samples
    tail = rss_prefix(t[::-1], x[::-1])[::-1]  # tail[j]: rss of samples j..n-1
    j = np.arange(MIN_SEGMENT, n - MIN_SEGMENT + 1)
    return j, head[j - 1] + tail[j]


def find_steps(t, x, steps: int = 1) -> tuple[list[float], list[float]]:
    """(times [s] at which the load-point velocity steps, velocities [m/s] of the segments) from the
    displacement record: one breakpoint at a time, each splitting the segment whose two-line fit gains most."""
    bounds = [0, len(t)]
    for _ in range(steps):
        best = None
        for a, b in zip(bounds[:-1], bounds[1:]):
            if b - a < 2 * MIN_SEGMENT:
                continue
            j, rss = _line_fit_rss(t[a:b], x[a:b])
            k = int(np.argmin(rss))
            gain = _line_fit_rss_one(t[a:b], x[a:b]) - rss[k]
            if best is None or gain > best[0]:
                best = (gain, a + int(j[k]))
        if best is None:
            raise DatasetError(f"too few samples to find {steps} velocity step(s)")
        bounds = sorted(bounds + [best[1]])
    lines = [np.polyfit(t[a:b], x[a:b], 1) for a, b in zip(bounds[:-1], bounds[1:])]
    # each step where the two lines beside it cross (not at a sample: the step falls between samples)
    times = [float(np.clip((c2 - c1) / (v1 - v2), t[j - 1], t[j])) if v1 != v2 else float(t[j])
             for j, (v1, c1), (v2, c2) in zip(bounds[1:-1], lines[:-1], lines[1:])]
    return times, [float(v) for v, _ in lines]


def _line_fit_rss_one(t, x) -> float:
    p = np.polyfit(t, x, 1)
    return float(np.sum((x - np.polyval(p, t)) ** 2))


def stiffness_guess(t, mu, t_step: float, v_before: float, v_after: float, span: float = 1.0) -> float | None:
    """k [1/m] from d mu/dt = k (V_lp - v) just after a step, while the slider still slides at v_before:
    the slope of mu over the first ``span`` seconds after the step over (v_after - v_before); None if unusable."""
    sel = (t > t_step) & (t <= t_step + span)
    if sel.sum() < 3 or v_after == v_before:
        return None
    k = float(np.polyfit(t[sel], mu[sel], 1)[0]) / (v_after - v_before)
    return k if k > 0 and math.isfinite(k) else None


def pick_samples(t, step_times, points: int) -> np.ndarray:
    """Indices of about ``points`` samples: uniform in time before the first step, and after each step
    at times growing geometrically from the sampling interval, where the transient is fast, to its end."""
    dt = float(np.median(np.diff(t)))
    edges = [t[0]] + list(step_times) + [t[-1]]
    share = max(points // (len(edges) - 1), 4)
    wanted = [np.linspace(edges[0], edges[1], share, endpoint=False)]
    for a, b in zip(edges[1:-1], edges[2:]):
        wanted.append(a + np.geomspace(dt, max(b - a, 2 * dt), share))
    idx = np.searchsorted(t, np.concatenate(wanted))
    return np.unique(np.clip(idx, 0, len(t) - 1))


def rice_sigma(y) -> float:
    """Difference-based noise estimate (Rice 1984): sigma^2 = sum (y_{i+1} - y_i)^2 / (2 (n - 1))."""
    d = np.diff(np.asarray(y, dtype=float))
    return float(math.sqrt(np.sum(d * d) / (2 * len(d))))


@attrs.frozen
class Imported:
    """What the importer found and chose, in SI units (for the TOML and for tests)."""

    time_zero: float
    step_times: tuple  # relative to time_zero [s]
    velocities: tuple  # [m/s]
    stiffness: float  # [1/m]
    stiffness_stated: bool
    trend: float  # removed slope d mu / dx [1/m] (0: none)
    sigma: float  # Rice estimate on the raw record [-]
    normal_stress: float  # mean [Pa]
    index: np.ndarray = attrs.field(eq=False)  # kept samples
    mu: np.ndarray = attrs.field(eq=False)  # friction after the trend removal, all samples


def analyse(raw: RawRecord, steps: int = 1, points: int = 600, detrend: bool = False,
            stiffness: float | None = None) -> Imported:
    """Find steps and velocities, the stiffness (given, or estimated), the trend, the noise and the samples."""
    times, velocities = find_steps(raw.t, raw.x, steps)
    velocities = [float(f"{v:.3g}") for v in velocities]  # the machine's set points, to 3 significant digits
    if min(velocities) <= 0:
        raise DatasetError(f"{raw.path}: a segment's load point does not advance ({min(velocities):.3g} m/s): "
                           "not a velocity-step record")
    mu, trend = raw.mu, 0.0
    if detrend:
        before = raw.t < times[0]
        trend = float(np.polyfit(raw.x[before], raw.mu[before], 1)[0])
        mu = raw.mu - trend * (raw.x - raw.x[0])
    stated = stiffness is not None
    if stiffness is None:
        stiffness = stiffness_guess(raw.t, mu, times[0], velocities[0], velocities[1])
        if stiffness is None:
            raise DatasetError(f"{raw.path}: cannot estimate the machine stiffness from the loading after the step; "
                               "give it with --stiffness (e.g. '0.01 1/um')")
    return Imported(time_zero=float(raw.t[0]), step_times=tuple(tt - raw.t[0] for tt in times),
                    velocities=tuple(velocities), stiffness=float(stiffness), stiffness_stated=stated, trend=trend,
                    sigma=rice_sigma(raw.mu), normal_stress=float(np.mean(raw.sn)),
                    index=pick_samples(raw.t, times, points), mu=mu)


def velstep_dataset(raw_path, name: str, *, steps: int = 1, points: int = 600, detrend: bool = False,
                    stiffness: float | None = None, source: str = "", license: str = "", citation: str = "",
                    command: str = "") -> tuple[str, str, Imported]:
    """(TOML text, CSV text, what was found) of a measured spring-slider dataset from one raw record."""
    check_name(name, "datasets import: --name", DatasetError)
    raw = read_raw(raw_path)
    imp = analyse(raw, steps, points, detrend, stiffness)
    toml = velstep_toml(name, raw, imp, source=source, license=license, citation=citation, command=command)
    rows = [f"# Samples of {raw.path.name} kept by frictionlab datasets import velstep (picked, not averaged);",
            "# t in the record's clock (time_zero in the TOML is t = 0), x load-point displacement, mu friction"
            + (" after removing the slip trend measured before the step" if detrend else ""),
            "t,x,mu"]
    rows += [f"{raw.t[i]:.10g},{raw.x[i] * 1e6:.10g},{imp.mu[i]:.8g}" for i in imp.index]
    return toml, "\n".join(rows) + "\n", imp


def _q(text: str) -> str:
    """A TOML basic string."""
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def velstep_toml(name: str, raw: RawRecord, imp: Imported, *, source: str, license: str, citation: str,
                 command: str) -> str:
    """The TOML of an imported velocity-step record (provenance 'measured')."""
    v_um = [f"{v * 1e6:g} um/s" for v in imp.velocities]
    k_note = ("given with --stiffness: a start; fit it with --free spring.stiffness" if imp.stiffness_stated else
              "estimated from d mu/dt = k (V_lp - v) over 1 s after the step: a start; fit it with --free "
              "spring.stiffness")
    trend = (f"friction's slip trend {imp.trend * 1e-6:.4g} per um, fitted to the samples before the step "
             "(slope S1 of Giacomel et al. 2024), removed over the whole record" if imp.trend else "no trend removed")
    method = (f"{len(imp.index)} of {len(raw.t)} samples of {raw.path.name} kept (picked, uniform before the step, "
              f"geometric in time after it); load-point velocities {', '.join(v_um)} and the step time from a "
              f"piecewise straight-line fit of displacement against time (3 significant digits); {trend}; "
              f"noise: Rice (1984) difference estimate on the raw record")
    lines = [
        f"# Imported by `frictionlab datasets import velstep` from {raw.path.name}: measured data; do not edit by hand.",
        f"name = {_q(name)}",
        'kind = "spring-slider"',
        'observable = "mu"',
        f"description = {_q(f'Velocity step {v_um[0]} -> {v_um[-1]} at {imp.normal_stress / 1e6:.4g} MPa {raw.stress} (record {raw.path.name}). MEASURED.')}",
        f'time_zero = "{imp.time_zero:.10g} s"   # the record\'s clock at its first sample',
        "",
        "[columns]",
        't = "s"',
        'x = "um"                   # load-point displacement',
        'mu = ""',
        "",
        "[noise]                    # sigma estimated from these samples (below, for reference: the Rice difference",
        'kind = "estimated"         # estimate on the raw record)',
        f"mu = {imp.sigma:.3g}",
        "",
        "[scene]",
        'mass = "1 kg"              # not used by a quasi-static slider',
        "",
        f"[scene.normal]             # the mean {raw.stress} on a unit area: only a slider's inertia reads it",
        'model = "constant"',
        f'value = "{imp.normal_stress:.6g} N"',
        "",
        "[scene.spring]",
        f'stiffness = "{imp.stiffness * 1e-6:.4g} 1/um"   # {k_note}',
        "times = [" + ", ".join(f'"{tt:.6g} s"' for tt in (0.0,) + imp.step_times) + "]",
        "velocities = [" + ", ".join(f'"{v}"' for v in v_um) + "]",
        "",
        "[provenance]",
        'kind = "measured"',
        f"source = {_q(source or str(raw.path))}",
    ]
    lines += [f"license = {_q(license)}"] if license else []
    lines += [f"citation = {_q(citation)}"] if citation else []
    lines += [f"method = {_q(method)}", f"command = {_q(command)}"] if command else [f"method = {_q(method)}"]
    return "\n".join(lines) + "\n"
