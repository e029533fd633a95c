"""Raw laboratory velocity-step records in, measured spring-slider datasets (CSV + TOML) out.

The raw format is the steadystate routine's (Giacomel et al., Geosphere 2024): a header line, then
whitespace- (or comma-) separated rows of time [s], load-point displacement [um], friction [-] and
(effective) normal stress [MPa]. A record may hold any number of velocity steps and holds. The importer

* segments the displacement into straight pieces (``segment``): every step's time is the kink of a
  continuous two-line fit, its velocities the fitted ones (not the machine's nominal set points), each with
  its standard error; transducer resets (jumps without a change of slope) are stitched;
* lays out the datasets: one per step, its window starting at a steady state the data show (``steadystate``:
  the first new steady-state point after the step before, or the record's) and ending in the steady part
  after its step, so that no window starts inside another step's transient (steps between which the record
  shows no steady state, as around a hold, share one window); or one dataset holding every step from the
  record's first steady state (``joint``), fitted as one history;
* estimates a start for the machine stiffness from friction's initial slope after each step, over a run of
  samples chosen from the data (the shortest that gives the slope to 10 %), whatever the transient's length;
* states the friction noise as estimated from the data with an AR(p) model chosen by the data (no sigma is written).
"""
from __future__ import annotations

import io
import math
import re
from pathlib import Path

import attrs
import numpy as np

from ..core.errors import DatasetError
from ..core.files import MAX_CSV_BYTES, read_bytes
from ..core.names import check_name
from .layout import cells, separator
from .rawrecord import RawRecord, check_record
from .segment import Segmentation, segment
from .segment_noise import last_digit

#: Header names accepted for the four raw columns (case-insensitive; '_' or nothing between words).
RAW_HEADER = (r"time\(s\)", r"displ(acement)?\(microns\)", r"friction", r"(effective_?)?normal_?stress\(mpa\)")
#: The stiffness start [1/m] (0.01 1/um, a typical laboratory value) where friction shows no loading after a step.
DEFAULT_STIFFNESS = 1e4


def read_raw(path, data: bytes | None = None, columns=None) -> RawRecord:
    """Read a raw velocity-step record (``data``: its bytes, already read) in the steadystate routine's layout,
    or in the layout ``columns`` gives (``"time=NAME UNIT, displacement=NAME UNIT, friction=NAME"``, or with
    ``shear=NAME UNIT, normal=NAME UNIT`` instead of friction: see ``io.layout``); UTF-8 or UTF-16 text. A
    one-line DatasetError (UnitError, ParameterError for ``columns``) naming the file and line on bad content (a
    bad number, a missing column, time that does not increase by at least ``rawrecord.MIN_DT``, magnitudes
    beyond ``rawrecord.LIMITS``, a normal stress that is not positive)."""
    import pandas as pd

    from .layout import decode, parse_columns

    path = Path(path)
    layout = parse_columns(columns, "columns") if columns is not None else None
    data = read_bytes(path, MAX_CSV_BYTES) if data is None else data
    data, encoding = decode(path, data)
    if layout is not None:
        return _read_layout(path, data, layout, encoding)
    head = re.match(rb"(?:[ \t\r\f\v]*\n)*([^\n]*)(?:\n|$)", data)
    header_no = data.count(b"\n", 0, head.start(1)) + 1
    header_text = head.group(1).decode("utf-8", "replace").strip()
    header = cells(header_text, separator(header_text))
    if not header_text:
        raise DatasetError(f"{path}: file is empty")
    if len(header) != 4 or not all(re.fullmatch(p, h, re.IGNORECASE) for p, h in zip(RAW_HEADER, header)):
        raise DatasetError(f"{path}: line {header_no}: header {header_text[:80]!r}; expected four columns: "
                           "Time(s) Displ(microns) Friction EffectiveNormalstress(MPa) (or NormalStress(MPa)), "
                           "or give the file's own with --columns")
    if b"," in data or b";" in data:
        data = data.replace(b",", b" ").replace(b";", b" ")
    body = memoryview(data)[head.end():]
    try:
        table = pd.read_csv(io.BytesIO(body), sep=r"\s+", header=None, dtype=float, engine="c",
                            skip_blank_lines=True).to_numpy()
        ok = table.ndim == 2 and table.shape[1] == 4 and bool(np.isfinite(table).all())
    except (ValueError, pd.errors.ParserError, pd.errors.EmptyDataError):
        ok, table = False, None
    blank = re.search(rb"(?:^|\n)[ \t\r\f\v]*(?:\n|$)", bytes(body).rstrip()) if b"\n\n" in data or b"\n " in data \
        or b"\n\t" in data or b"\n\r" in data else None
    lines = _lines(bytes(body).decode("utf-8", "replace"), header_no) if (blank or not ok) else None
    if not ok:
        _bad_row(path, bytes(body).decode("utf-8", "replace"), lines)
    del body, data
    first = header_no + 1
    rec = RawRecord(path=path, t=table[:, 0].copy(), x_um=table[:, 1].copy(), mu=table[:, 2].copy(),
                    sn=table[:, 3] * 1e6,
                    stress="effective normal stress" if "effective" in header[3].lower() else "normal stress",
                    first_line=first, lines=lines, encoding=encoding)
    check_record(rec)
    return rec


def _read_layout(path, data: bytes, layout, encoding: str = "") -> RawRecord:
    """The RawRecord in the columns of ``layout`` (io.layout) of a record's text (UTF-8 bytes; ``encoding``: what
    it was read as, when not UTF-8), friction from shear over normal when it has no friction column."""
    from .layout import read_table

    tab = read_table(path, data.decode("utf-8"), layout)
    v, normal = tab.values, layout["normal"]
    sn = v.get("normal")
    mu = v.get("friction")
    if mu is None:
        bad = np.flatnonzero(~(sn > 0))
        if bad.size:
            i = int(bad[0])
            raise DatasetError(f"{path}: line {tab.lines[i]}: normal={normal.name} is {sn[i] / normal.factor:g} "
                               f"{normal.unit}; friction is shear / normal, which needs a positive normal "
                               f"{'force' if normal.force else 'stress'}")
        mu = v["shear"] / sn
    stress = "" if normal is None else "normal force" if normal.force else "normal stress"
    rec = RawRecord(path=path, t=v["time"], x_um=v["displacement"] * 1e6, mu=mu, sn=sn, stress=stress,
                    first_line=int(tab.lines[0]), lines=tab.lines, encoding=encoding, layout=layout.text(),
                    notes=tab.notes + ((f"friction = {layout['shear'].name} / {normal.name}",)
                                       if layout["shear"] else ()))
    check_record(rec)
    return rec


def _lines(body: str, header_no: int) -> np.ndarray:
    """The line of each non-blank line of ``body`` (which starts on the line after ``header_no``)."""
    return np.array([header_no + 1 + k for k, s in enumerate(body.split("\n")) if s.strip()], dtype=np.int64)


def _bad_row(path: Path, body: str, lines) -> None:
    """The one-line error for the first row that is not four finite numbers."""
    rows = [s for s in body.split("\n") if s.strip()]
    for no, row in zip(lines, rows):
        try:
            values = [float(p) for p in row.split()]
        except ValueError:
            values = []
        if len(values) != 4 or not all(math.isfinite(v) for v in values):
            raise DatasetError(f"{path}: line {no}: expected four finite numbers, got {row.strip()[:60]!r}")
    raise DatasetError(f"{path}: no data rows after the header")


# --- what the import finds --------------------------------------------------------------------------
@attrs.frozen
class Window:
    """One dataset's samples [a, b) and its load-point schedule: times relative to the window's first sample
    [s], velocities [m/s] (fitted), the stiffness start [1/m] and how it was obtained."""

    name: str
    a: int
    b: int
    times: tuple
    velocities: tuple
    stiffness: float
    stiffness_note: str
    steps: tuple  # indices of the Steps it holds
    start_note: str = ""  # where the window starts and why (a steady state the data show)

    @property
    def stiffness_from(self) -> str:
        """'given', 'estimated' or 'a typical value' (the first word of how the start was obtained)."""
        note = self.stiffness_note
        return "given" if note.startswith("given") else "a typical value" if "typical" in note else "estimated"


@attrs.frozen(eq=False)
class Imported:
    """What the importer found and chose, in SI units."""

    raw: RawRecord
    seg: Segmentation
    windows: tuple  # Window per dataset
    velocities: tuple  # each piece's load-point velocity as written [m/s] (a hold within its error: 0)
    notes: tuple  # sentences for the user (jumps stitched, holds, starts in a hold)

    @property
    def x_um(self) -> np.ndarray:
        """Load-point displacement [um], jumps stitched."""
        return self.seg.x


def analyse(raw: RawRecord, name: str, *, joint: bool | None = False, stiffness: float | None = None,
            steps: int | None = None) -> Imported:
    """Segment the record, check it, and lay out its datasets: one per step (``name`` alone for a record of
    one step, else name-step1, name-step2, ...), or one holding every step (``joint``; None: when there are
    several). ``stiffness`` [1/m]: the start of every dataset instead of the estimate; ``steps``: the number of
    steps expected (an error if another number is found)."""
    where = str(raw.path)
    if float(np.ptp(raw.mu)) == 0.0:
        raise DatasetError(f"{where}: friction is {raw.mu[0]:g} at every sample (lines {raw.line(0)} to "
                           f"{raw.line(len(raw.mu) - 1)}): a constant channel has nothing to fit (is it the friction "
                           "column?)")
    seg = segment(raw.t, raw.x_um, where, raw.line, "um")  # in the record's units: um, um/s
    m = len(seg.steps)
    joint = m > 1 if joint is None else joint
    if steps is not None and steps != m:
        found = ", ".join(f"line {raw.line(s.index)} (t = {s.time:.6f} s)" for s in seg.steps)
        raise DatasetError(f"{where}: expected {steps} velocity step{'s' * (steps != 1)} (--steps), found {m}: {found}")
    velocities, notes = _velocities(raw, seg)
    if seg.exact_to:
        notes.append(f"the displacement shows no noise beyond its last digit ({seg.exact_to:.3g} um): the standard "
                     "errors are bounds of the rounding to it, which errs alike at every sample of a line sampled "
                     "exactly, not a scatter")
    notes += [f"displacement jump of {j.size:.4g} ± {j.size_se:.2g} um at line {raw.line(j.index)} "
              f"(t = {raw.t[j.index]:.10g} s) without a change of velocity: stitched (later samples shifted back)"
              for j in seg.jumps]
    b = seg.bounds
    ks = [stiffness_start(raw.t, raw.mu, s, velocities[i], velocities[i + 1], b[i], b[i + 2])
          for i, s in enumerate(seg.steps)]
    if stiffness is None and all(k is None for k in ks):
        notes.append(f"friction shows no loading after any step (no initial slope to 10 %): the stiffness start is "
                     f"{DEFAULT_STIFFNESS * 1e-6:g} 1/um, a typical laboratory value, to be fitted with the law")

    def start(i):
        if stiffness is not None:
            return stiffness, "given with --stiffness: a start, fitted with the law"
        if ks[i]:
            return ks[i][0], (f"start: friction's initial slope after the step, over the first {ks[i][1]:.3g} s (the "
                              "shortest run that gives it to 10 %), over the load-point velocity change")
        if any(ks):
            return next(k for k in ks if k)[0], "start taken from another step of the record (this one's loading " \
                                                "gives none)"
        return DEFAULT_STIFFNESS, "start: a typical laboratory value (friction shows no loading after the step)"

    windows = []
    from .steadystate import left_out, start_note, steady_points, step_windows

    points = steady_points(seg.x, raw.mu, b, velocities)
    if joint:
        k, note = start(0)
        if stiffness is None and any(ks):
            k = float(np.median([k[0] for k in ks if k]))
            note = "start: the median over the steps of friction's initial slope after each step over the " \
                   "load-point velocity change"
        a = next((p.index for p in points[:1] if p.found), 0)
        windows.append(Window(name, a, len(raw.t), (0.0,) + tuple(float(s.time - raw.t[a]) for s in seg.steps),
                              tuple(velocities), k, note, tuple(range(m)), start_note(raw, points, a, None)))
    else:
        for a, e, held in step_windows(points, b):
            kv, note = start(held[0])
            windows.append(Window(name if m == 1 else f"{name}-step{held[0] + 1}", a, e,
                                  (0.0,) + tuple(float(seg.steps[i].time - raw.t[a]) for i in held),
                                  tuple(velocities[held[0]:held[-1] + 2]), kv, note, held,
                                  start_note(raw, points, a, held)))
        notes += [f"step {i + 1} has no window of its own: {why}" for i, why in left_out(points, m)]
    for w in windows:
        check_name(w.name, "datasets import: --name", DatasetError)
    return Imported(raw=raw, seg=seg, windows=tuple(windows), velocities=tuple(velocities), notes=tuple(notes))


def _velocities(raw: RawRecord, seg: Segmentation) -> tuple[list[float], list[str]]:
    """The pieces' velocities as written [m/s]: fitted, a hold (within 3 standard errors of 0) as 0; a load
    point that moves backwards is refused."""
    out, notes = [], []
    for k, (v, se) in enumerate(zip(np.array(seg.velocities) * 1e-6, np.array(seg.velocities_se) * 1e-6)):
        a, b = seg.bounds[k], seg.bounds[k + 1]
        span = f"lines {raw.line(a)} to {raw.line(b - 1)} (t = {raw.t[a]:.10g} to {raw.t[b - 1]:.10g} s)"
        if abs(v) <= 3 * se:
            out.append(0.0)
            notes.append(f"hold from {span}: fitted {v * 1e6:.3g} ± {se * 1e6:.2g} um/s, written as 0")
        elif v < 0:
            raise DatasetError(f"{raw.path}: the load point moves backwards ({v * 1e6:.4g} um/s) from {span}; a "
                               "velocity-step record's load point advances or holds")
        else:
            out.append(float(v))
    return out, notes


def stiffness_start(t, mu, step, v1: float, v2: float, a: int, b: int) -> tuple[float, float] | None:
    """(k [1/m], duration [s]) from d mu/dt = k (V_lp - v) while the slider still slides at about v1: the
    initial slope of friction after the step over (v2 - v1), fitted over the shortest run of samples from the
    step (3, 4, 6, 8, ... up to the next step ``b``) that gives it to 10 % (the loading transient, whatever
    its length and sampling); None when friction does not move towards the new velocity's level."""
    i0 = step.index
    if v2 == v1 or b - i0 < 3:
        return None
    sgn = 1.0 if v2 > v1 else -1.0
    best, n = None, 3
    while True:
        u, y = t[i0:i0 + n] - t[i0], mu[i0:i0 + n]
        slope, icpt = np.polyfit(u, y, 1)
        resid = y - (slope * u + icpt)
        se = math.sqrt(float(resid @ resid) / max(n - 2, 1) / float(np.sum((u - u.mean()) ** 2)))
        if sgn * slope > 0 and (best is None or se / abs(slope) < best[2]):
            best = (float(slope), float(u[-1]), se / abs(slope))
        if (best is not None and best[2] <= 0.1) or i0 + n >= b:
            break
        n = min(max(n + 1, int(n * 1.41)), b - i0)
    if best is None or best[2] > 0.1:
        return None
    if abs(best[0]) * best[1] <= max(last_digit(mu[i0:b]), 1e-12 * float(np.max(np.abs(mu[i0:b])))):
        return None  # a change below the channel's last digit: no loading seen
    k = best[0] / (v2 - v1)
    return (k, best[1]) if k > 0 and math.isfinite(k) else None


# --- the files ---------------------------------------------------------------------------------------
def _q(text: str) -> str:
    """A TOML basic string."""
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _time(s: float) -> str:
    """A time [s] to the nanosecond, trailing zeros dropped."""
    return f"{s:.9f}".rstrip("0").rstrip(".") + " s"


def _um(v: float) -> str:
    return f"{v * 1e6:.7g} um/s"


def dataset_toml(imp: Imported, w: Window, *, source: str = "", license: str = "", citation: str = "",
                 command: str = "") -> str:
    """The TOML of one imported window (provenance 'measured')."""
    raw, seg = imp.raw, imp.seg
    steps = [seg.steps[i] for i in w.steps]
    v_text = " -> ".join(f"{v * 1e6:.4g}" for v in w.velocities)
    stress = float(np.mean(raw.sn[w.a:w.b])) if raw.sn is not None else None
    fitted = "; ".join(f"step at {s.time - raw.t[w.a]:.6f} ± {s.time_se:.2g} s" for s in steps)
    fitted_v = ", ".join(f"{v:.7g} ± {seg.velocities_se[k]:.2g}"
                         for k, v in enumerate(seg.velocities) if k in _pieces(w))
    jumps = [j for j in seg.jumps if w.a < j.index < w.b]
    read = "; ".join(([f"read as {raw.encoding}"] if raw.encoding else []) +
                     ([f"columns {raw.layout}"] if raw.layout else []) + list(raw.notes))
    method = (f"every sample of {raw.span(w.a, w.b)} ({w.b - w.a} samples"
              f"{'; ' + read if read else ''}); load-point "
              f"velocities and step time{'s' * (len(steps) > 1)} from an exact piecewise-linear segmentation of the "
              f"displacement (optimal partitioning, PELT, penalty 3 ln n = {seg.penalty:.1f}; "
              f"{len(seg.steps)} step{'s' * (len(seg.steps) != 1)} in the record), each step at the kink of a "
              "continuous two-line fit, velocities from one continuous fit through every kink (fitted values, not "
              "set points)" + (f"; {len(jumps)} displacement jump{'s' * (len(jumps) != 1)} without a change of "
                               "velocity stitched" if jumps else "") +
              "; friction as measured (no trend removed); its noise estimated with the fit, AR(p) chosen by the data" +
              (f"; the window {w.start_note}" if w.start_note else ""))
    at = f" at {raw.normal_text(stress)}" if stress is not None else ""
    description = (f"Velocity step{'s' * (len(steps) > 1)} {v_text} um/s{at} "
                   f"({raw.span(w.a, w.b)}). MEASURED.")
    lines = [
        f"# Imported by `frictionlab datasets import velstep` from {raw.path.name}: measured data; do not edit by hand.",
        f"name = {_q(w.name)}",
        'kind = "spring-slider"',
        'observable = "mu"',
        f"description = {_q(description)}",
        f'time_zero = "{float(raw.t[w.a])!r} s"   # the record\'s clock at {raw.where(w.a)}',
        "",
        "[columns]",
        't = "s"',
        'x = "um"                   # load-point displacement' + (" (jumps stitched)" if jumps else ""),
        'mu = ""',
        "",
        "[noise]                    # friction's noise: estimated with the fit, AR(p) chosen by the data",
        'kind = "estimated"',
        'correlation = "arp"',
        "",
        "[scene]",
        'mass = "1 kg"              # not used by a quasi-static slider',
        "",
        f"[scene.normal]             # the mean {raw.stress} on a unit area: only a slider's inertia reads it"
        if stress is not None else "[scene.normal]             # the record has no normal load: a unit load (only a "
                                   "slider's inertia reads it)",
        'model = "constant"',
        f'value = "{stress if stress is not None else 1.0:.6g} N"',
        "",
        "[scene.spring]",
        f'stiffness = "{w.stiffness * 1e-6:.4g} 1/um"   # {w.stiffness_note}',
        "times = [" + ", ".join(f'"{_time(s)}"' for s in w.times) + f"]   # fitted: {fitted}",
        "velocities = [" + ", ".join(f'"{_um(v)}"' for v in w.velocities) + f"]   # fitted: {fitted_v} um/s",
        "",
        "[provenance]",
        'kind = "measured"',
        f"source = {_q(source or str(raw.path))}",
    ]
    lines += [f"license = {_q(license)}"] if license else []
    lines += [f"citation = {_q(citation)}"] if citation else []
    lines += [f"method = {_q(method)}"] + ([f"command = {_q(command)}"] if command else [])
    return "\n".join(lines) + "\n"


def _pieces(w: Window) -> range:
    """The pieces (between steps) a window covers."""
    return range(w.steps[0], w.steps[-1] + 2)


CSV_HEADER = "t,x,mu"


def write_csv(fh, imp: Imported, w: Window) -> None:
    """Every sample of the window as t [s, the record's clock], x [um, jumps stitched, to 1e-9 um], mu, written
    in chunks, each number as read (the shortest text that gives it back)."""
    raw = imp.raw
    fh.write(f"# Every sample of {raw.span(w.a, w.b)}, as recorded "
             f"(x: load-point displacement{', jumps stitched' if any(w.a < j.index < w.b for j in imp.seg.jumps) else ''}"
             "); t in the record's clock (time_zero in the TOML is t = 0)\n" + CSV_HEADER + "\n")
    for lo in range(w.a, w.b, 100_000):
        hi = min(lo + 100_000, w.b)
        cols = (raw.t[lo:hi].tolist(), np.round(imp.x_um[lo:hi], 9).tolist(), raw.mu[lo:hi].tolist())
        fh.write("\n".join(f"{a!r},{b!r},{c!r}" for a, b, c in zip(*cols)) + "\n")


def columns(imp: Imported, w: Window, rows: int | None = None) -> dict:
    """The CSV's columns as the dataset reader returns them (file units: s, um, -); ``rows``: at most that
    many, evenly spread from the window's first sample to its last."""
    idx = slice(w.a, w.b) if rows is None or w.b - w.a <= rows else \
        np.unique(np.linspace(w.a, w.b - 1, rows).astype(np.int64))
    return {"t": imp.raw.t[idx], "x": imp.x_um[idx], "mu": imp.raw.mu[idx]}


def parts(imp: Imported, w: Window, toml_text: str, rows: int | None = None) -> tuple[dict, dict]:
    """(TOML table, CSV columns) of one window, from its TOML text and the arrays in memory: what
    ``dataset.from_meta`` builds the Dataset from once the pair is written (``rows``: a check on at most that
    many samples, spread over the window)."""
    import tomllib

    return tomllib.loads(toml_text), columns(imp, w, rows)


def summary(imp: Imported) -> list[str]:
    """What the import found, as lines of text: the record, its noise and the table of steps."""
    raw, seg = imp.raw, imp.seg
    n, m = len(raw.t), len(seg.steps)
    out = [f"{raw.path.name}: {n} samples, t = {raw.t[0]:.10g} to {raw.t[-1]:.10g} s; displacement noise "
           f"{seg.noise:.3g} um; {m} velocity step{'s' * (m != 1)} (segmentation penalty 3 ln n = "
           f"{seg.penalty:.1f}), {len(seg.jumps)} jump{'s' * (len(seg.jumps) != 1)} stitched"]
    rows = [("step", "line", "time [s]", "V before [um/s]", "V after [um/s]", "samples before + after")]
    for i, s in enumerate(seg.steps):
        b = seg.bounds
        rows.append((str(i + 1), raw.where(s.index).removeprefix("line "), _pm(s.time, s.time_se),
                     _pm(imp.velocities[i] * 1e6, seg.velocities_se[i]),
                     _pm(imp.velocities[i + 1] * 1e6, seg.velocities_se[i + 1]),
                     f"{b[i + 1] - b[i]} + {b[i + 2] - b[i + 1]}"))
    widths = [max(len(r[j]) for r in rows) for j in range(len(rows[0]))]
    out += ["  " + "  ".join(c.ljust(wd) for c, wd in zip(r, widths)).rstrip() for r in rows]
    read = ([f"read as {raw.encoding}"] if raw.encoding else []) + list(raw.notes)
    out += [f"  note: {note}" for note in read + list(imp.notes)]
    return out


def _pm(v: float, se: float) -> str:
    """'v ± se' with se to two significant digits and v to the same decimal place."""
    if not (se > 0 and math.isfinite(se)):
        return f"{v:.7g}"
    d = max(0, 1 - math.floor(math.log10(se)))
    return f"{v:.{d}f} ± {se:.{d}f}"
