"""Several raw files of one experiment read as one record: the experiment's whole load-point history.

A laboratory often saves one experiment in slices (the steadystate routine's sepiolite experiment is three
files, each around one velocity step, overlapping in time). ``read_joined`` reads every file (``velstep.read_raw``),
orders them by their first time and joins them by time: where two files overlap, the samples of the overlap
must be the same samples (the same times, displacements, friction and normal stress, as a slice of one
recording is); a sample of the later file beyond the earlier one's end is appended. Nothing is copied: the
joined record lives in memory, and the datasets written from it name every file and the line of each sample
in its own file.
"""
from __future__ import annotations

from pathlib import Path

import attrs
import numpy as np

from ..core.errors import DatasetError
from .rawrecord import RawRecord
from .velstep import read_raw


@attrs.frozen(eq=False)
class JoinedRecord(RawRecord):
    """A RawRecord joined from ``files`` (in time order); ``source[i]``: the file of sample i, ``lines[i]`` its line
    there. ``path`` is the first file's folder with the files' names joined by '+'."""

    files: tuple = ()
    source: np.ndarray | None = None

    def where(self, i: int) -> str:
        """'FILE line N' of sample i."""
        return f"{self.files[int(self.source[i])].name} line {self.line(i)}"

    def span(self, a: int, b: int) -> str:
        """'FILE line A to FILE line B' of samples [a, b)."""
        return f"{self.where(a)} to {self.where(b - 1)}"


def read_joined(paths, columns=None) -> RawRecord:
    """One record from the raw files ``paths`` of one experiment, each read by ``read_raw`` in the layout
    ``columns`` gives (None: the steadystate layout; one path: that file as read); a one-line
    DatasetError naming both files where they overlap with different samples or mix stress columns."""
    paths = [Path(p) for p in paths]
    if len(paths) == 1:
        return read_raw(paths[0], columns=columns)
    if len({p.resolve() for p in paths}) != len(paths):
        raise DatasetError(f"{', '.join(map(str, paths))}: a file is named twice")
    recs = sorted((read_raw(p, columns=columns) for p in paths), key=lambda r: float(r.t[0]))
    stress = {r.stress if r.sn is not None else "no normal stress" for r in recs}
    if len(stress) > 1:
        raise DatasetError(f"{recs[0].path} and {recs[-1].path}: one experiment's files must record the same normal "
                           f"stress column, got {' and '.join(sorted(stress))}")
    t, x, mu, sn, src, lines = [], [], [], [], [], []
    end = -np.inf
    for k, r in enumerate(recs):
        own = np.array([r.line(i) for i in range(r.t.size)], dtype=np.int64) if r.lines is None else r.lines
        new = r.t > end
        overlap = np.flatnonzero(~new)
        if overlap.size:
            _check_overlap(recs[k - 1], r, overlap, np.concatenate(t), np.concatenate(x), np.concatenate(mu),
                           None if r.sn is None else np.concatenate(sn))
        t.append(r.t[new]), x.append(r.x_um[new]), mu.append(r.mu[new]), sn.append(None if r.sn is None else r.sn[new])
        src.append(np.full(int(new.sum()), k, dtype=np.int64)), lines.append(own[new])
        end = max(end, float(r.t[-1]))
    names = "+".join(r.path.name for r in recs)
    return JoinedRecord(path=recs[0].path.parent / names, t=np.concatenate(t), x_um=np.concatenate(x),
                        mu=np.concatenate(mu), sn=None if recs[0].sn is None else np.concatenate(sn), stress=recs[0].stress,
                        layout=recs[0].layout, encoding=recs[0].encoding,
                        notes=tuple(dict.fromkeys(n for r in recs for n in r.notes)),
                        first_line=int(lines[0][0]), lines=np.concatenate(lines),
                        files=tuple(r.path for r in recs), source=np.concatenate(src))


def _check_overlap(before: RawRecord, r: RawRecord, overlap, t, x, mu, sn) -> None:
    """The samples of ``r`` at indices ``overlap`` (times already joined) must be samples already read, value
    for value."""
    j = np.searchsorted(t, r.t[overlap])
    j = np.clip(j, 0, t.size - 1)
    same = (t[j] == r.t[overlap]) & (x[j] == r.x_um[overlap]) & (mu[j] == r.mu[overlap])
    if sn is not None:
        same &= sn[j] == r.sn[overlap]
    if not same.all():
        i = int(overlap[np.flatnonzero(~same)[0]])
        raise DatasetError(f"{r.path}: line {r.line(i)}: t = {r.t[i]:.10g} s lies within {before.path.name} "
                           f"(to t = {before.t[-1]:.10g} s) but is not the same sample there: the files are not "
                           "slices of one recording")
