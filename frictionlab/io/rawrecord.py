"""A raw laboratory record as read, in SI but for displacement (um, as recorded): time, displacement, friction
and normal stress or force, with the line of the file each sample came from, and the checks every reader applies
(magnitudes, time increments, a positive normal stress). Read by ``velstep.read_raw`` (the steadystate layout or any lab's columns)."""
from __future__ import annotations

from pathlib import Path

import attrs
import numpy as np

from ..core.errors import DatasetError
from .segment import MIN_PIECE

#: Smallest time increment of a record [s], and the largest magnitudes read (s, um, -, MPa).
MIN_DT = 1e-9
LIMITS = {"time": 1e12, "displacement": 1e12, "friction": 1e3, "normal stress": 1e6}


@attrs.frozen(eq=False)
class RawRecord:
    """One raw record: time [s], displacement [um, as recorded; ``x`` in m], friction [-], normal stress [Pa]
    or force [N] (``stress``: what the file's header calls it; ``sn`` None when the record has none), and the
    line of the file each sample was read from; ``encoding``, ``layout`` (the columns, as ``--columns`` takes
    them) and ``notes``: how it was read, when not as the steadystate routine writes it."""

    path: Path
    t: np.ndarray
    x_um: np.ndarray
    mu: np.ndarray
    sn: np.ndarray | None
    stress: str = "effective normal stress"
    first_line: int = 2  # line of the first sample when every line after the header holds one
    lines: np.ndarray | None = None  # line of each sample otherwise
    encoding: str = ""  # what the text was when not UTF-8, e.g. "UTF-16 (little-endian, without a byte-order mark)"
    layout: str = ""
    notes: tuple = ()

    @property
    def x(self) -> np.ndarray:
        """Displacement [m]."""
        return self.x_um * 1e-6

    def line(self, i: int) -> int:
        """The file's line (1-based) of sample i."""
        return int(self.lines[i]) if self.lines is not None else self.first_line + int(i)

    def normal_text(self, value: float) -> str:
        """A mean normal stress [Pa] or force [N] as the description says it: '30 MPa effective normal stress'."""
        return f"{value / 1e3:.4g} kN {self.stress}" if self.stress == "normal force" else \
            f"{value / 1e6:.4g} MPa {self.stress}"

    def where(self, i: int) -> str:
        """'line N' of sample i (a record joined from several files names the file too)."""
        return f"line {self.line(i)}"

    def span(self, a: int, b: int) -> str:
        """'lines A to B of FILE' of samples [a, b)."""
        return f"lines {self.line(a)} to {self.line(b - 1)} of {self.path.name}"


def check_record(rec: RawRecord) -> None:
    """Magnitudes, time increments and normal stress, each refused with the line of the first bad sample."""
    n = len(rec.t)
    if n < 2 * MIN_PIECE:
        raise DatasetError(f"{rec.path}: {n} data rows; a velocity step needs at least {MIN_PIECE} on either side")
    scale = 1e3 if rec.stress == "normal force" else 1e6
    cols = (rec.t, rec.x_um, rec.mu, None if rec.sn is None else rec.sn / scale)
    units = "the record's units (s, um, -, MPa)" if not rec.layout else \
        f"s, um, -, {'kN' if scale == 1e3 else 'MPa'} (the units they were converted to)"
    for col, (what, limit) in zip(cols, LIMITS.items()):
        bad = np.flatnonzero(np.abs(col) > limit) if col is not None else ()
        if len(bad):
            i = int(bad[0])
            raise DatasetError(f"{rec.path}: line {rec.line(i)}: {what} {col[i]:g} is beyond {limit:g} in {units}")
    dt = np.diff(rec.t)
    bad = np.flatnonzero(~(dt >= MIN_DT))
    if bad.size:
        i = int(bad[0]) + 1
        what = "does not increase" if dt[i - 1] <= 0 else f"increases by {dt[i - 1]:.3g} s"
        raise DatasetError(f"{rec.path}: line {rec.line(i)}: time {rec.t[i]:.10g} s {what} after line {rec.line(i - 1)} "
                           f"({rec.t[i - 1]:.10g} s); time must increase by at least {MIN_DT:g} s a sample")
    bad = np.flatnonzero(~(rec.sn > 0)) if rec.sn is not None else ()
    if len(bad):
        i = int(bad[0])
        raise DatasetError(f"{rec.path}: line {rec.line(i)}: normal {'force' if scale == 1e3 else 'stress'} must be "
                           f"positive, got "
                           f"{cols[3][i]:g} {'kN' if scale == 1e3 else 'MPa'}")
