"""Raw records in any laboratory's layout: which columns hold time, displacement and friction (or shear and
normal stress), in which units, and how the file's text is encoded and separated.

The layout is written as the command line's ``--columns`` and ``read_raw(columns=...)`` take it::

    time=NAME UNIT, displacement=NAME UNIT, friction=NAME [, normal=NAME UNIT]
    time=NAME UNIT, displacement=NAME UNIT, shear=NAME UNIT, normal=NAME UNIT      (mu = shear / normal)

NAME is the column's name in the file's header (case-insensitive; in quotes when it holds spaces or a comma)
or ``#N``, the N-th column counted from 1 (for a file without a header). UNIT is read by
``core.units.unit_factor``: any time (s, ms), length (m, mm, um), stress (Pa, kPa, MPa) or, for shear and
normal together, force (N, kN). Lines before the header and rows after it that are not numbers (a row of
units, say) are skipped and said; the separator (tab, comma, semicolon or spaces) is the header's.
"""
from __future__ import annotations

import io
import math
import re
import shlex

import attrs
import numpy as np

from ..core.errors import DatasetError, ParameterError, UnitError
from ..core.units import unit_factor

#: Each role and the SI unit of its values (normal and shear: a stress, or both a force).
ROLES = {"time": "s", "displacement": "m", "friction": "", "shear": "Pa", "normal": "Pa"}
EXAMPLE = "time=Time ms, displacement=Disp mm, shear=Tau MPa, normal=Sigma MPa"


@attrs.frozen
class Column:
    """One column of the layout: its role, its name in the header (or '#N'), its unit and the factor to SI."""

    role: str
    name: str
    unit: str
    factor: float
    force: bool = False  # shear or normal given as a force [N] rather than a stress [Pa]

    @property
    def position(self) -> int | None:
        """0-based column index for a '#N' name, else None."""
        return int(self.name[1:]) - 1 if re.fullmatch(r"#[1-9]\d*", self.name) else None

    def text(self) -> str:
        name = self.name if re.fullmatch(r"[^\s,'\"]+", self.name) else \
            f'"{self.name}"' if '"' not in self.name else shlex.quote(self.name)
        return f"{self.role}={name}" + (f" {self.unit}" if self.unit else "")


@attrs.frozen
class Layout:
    """The columns a record is read from, by role."""

    columns: tuple

    def __getitem__(self, role: str) -> Column | None:
        return next((c for c in self.columns if c.role == role), None)

    def text(self) -> str:
        """The layout as ``--columns`` takes it."""
        return ", ".join(c.text() for c in self.columns)


def parse_columns(spec, where: str = "--columns") -> Layout:
    """The layout written in ``spec`` (module docstring); a one-line ParameterError or UnitError naming
    ``where`` and the column at fault."""
    if isinstance(spec, Layout):
        return spec
    if not isinstance(spec, str) or not spec.strip():
        raise ParameterError(f"{where}: expected the columns as text like {EXAMPLE!r}, got {spec!r:.60}")
    cols: dict[str, tuple[str, str]] = {}
    for item in _items(spec, where):
        role, sep, value = item.partition("=")
        role = role.strip().lower()
        if not sep or not role:
            raise ParameterError(f"{where}: {item.strip()!r}: expected ROLE=NAME UNIT, like 'time=Time ms'")
        if role not in ROLES:
            raise ParameterError(f"{where}: unknown column {role!r}; expected {', '.join(ROLES)}")
        if role in cols:
            raise ParameterError(f"{where}: {role} is given twice")
        try:
            words = shlex.split(value)
        except ValueError as exc:
            raise ParameterError(f"{where}: {role}={value.strip()!r}: {exc}") from None
        if not words:
            raise ParameterError(f"{where}: {role}= names no column; write it like '{role}=NAME"
                                 f"{' UNIT' if ROLES[role] else ''}'")
        cols[role] = (words[0], " ".join(words[1:]))
    for role in ("time", "displacement"):
        if role not in cols:
            raise ParameterError(f"{where}: no {role} column; expected like {EXAMPLE!r}")
    if ("friction" in cols) == ("shear" in cols):
        raise ParameterError(f"{where}: give friction=NAME, or shear=NAME UNIT with normal=NAME UNIT "
                             "(friction = shear / normal), not " + ("both" if "friction" in cols else "neither"))
    if "shear" in cols and "normal" not in cols:
        raise ParameterError(f"{where}: shear needs normal=NAME UNIT (friction = shear / normal)")
    out = []
    for role in ROLES:
        if role in cols:
            out.append(_column(role, *cols[role], where))
    shear, normal = (next((c for c in out if c.role == r), None) for r in ("shear", "normal"))
    if shear is not None and shear.force != normal.force:
        raise UnitError(f"{where}: shear is a {'force' if shear.force else 'stress'} ({shear.unit}) and normal a "
                        f"{'force' if normal.force else 'stress'} ({normal.unit}): give both as stresses or both as "
                        "forces")
    names = [c.name.lower() for c in out]
    dup = next((n for n in names if names.count(n) > 1), None)
    if dup is not None:
        raise ParameterError(f"{where}: column {dup!r} is named for two roles")
    return Layout(tuple(out))


def _items(spec: str, where: str) -> list[str]:
    """The comma-separated items of ``spec``, commas inside quotes kept."""
    items, cur, quote = [], "", ""
    for ch in spec:
        if quote:
            quote = "" if ch == quote else quote
        elif ch in "'\"":
            quote = ch
        elif ch == ",":
            items.append(cur)
            cur = ""
            continue
        cur += ch
    items.append(cur)
    if any(not i.strip() for i in items):
        raise ParameterError(f"{where}: {spec!r:.80} holds an empty item (a stray comma?)")
    return items


def _column(role: str, name: str, unit: str, where: str) -> Column:
    field = f"{where}: {role}={name}"
    si = ROLES[role]
    if si and not unit:
        raise UnitError(f"{field}: no unit; write it like '{role}={name} {_like(role)}'")
    if role == "friction":
        return Column(role, name, unit, unit_factor(unit, "", field) if unit else 1.0)
    if role in ("shear", "normal"):
        try:
            return Column(role, name, unit, unit_factor(unit, "Pa", field))
        except UnitError:
            try:
                return Column(role, name, unit, unit_factor(unit, "N", field), force=True)
            except UnitError:
                raise UnitError(f"{field}: unit {unit!r} is neither a stress (like 'MPa') nor a force (like "
                                "'kN')") from None
    return Column(role, name, unit, unit_factor(unit, si, field))


def _like(role: str) -> str:
    return {"time": "s", "displacement": "um", "shear": "MPa", "normal": "MPa"}.get(role, "")


# --- the file's text ----------------------------------------------------------------------------------
def decode(path, data: bytes) -> tuple[bytes, str]:
    """(the record as UTF-8 bytes, what its encoding was when not UTF-8): UTF-8 with or without a byte-order
    mark, or UTF-16 with one or without (told by its zero bytes: every other byte of ASCII text); a one-line
    DatasetError otherwise."""
    if data.startswith(b"\xef\xbb\xbf"):
        return data[3:], ""
    enc, said = None, ""
    if data[:2] in (b"\xff\xfe", b"\xfe\xff"):
        enc = "utf-16"
        said = "UTF-16 (" + ("little" if data[:1] == b"\xff" else "big") + "-endian, with a byte-order mark)"
    elif b"\x00" in data[:4096]:
        head = data[:4096]
        even, odd = head[0::2].count(0), head[1::2].count(0)
        if odd > len(head) // 4 and even == 0:
            enc, said = "utf-16-le", "UTF-16 (little-endian, without a byte-order mark)"
        elif even > len(head) // 4 and odd == 0:
            enc, said = "utf-16-be", "UTF-16 (big-endian, without a byte-order mark)"
    if enc is not None:
        try:
            return data.decode(enc).encode("utf-8"), said
        except UnicodeDecodeError as exc:
            raise DatasetError(f"{path}: reads as {said} up to byte {exc.start + 1}, which is not: neither UTF-8 "
                               "nor UTF-16 text") from None
    if not data.isascii():
        try:
            data.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise DatasetError(f"{path}: not UTF-8 text (byte {exc.start + 1})") from None
    if b"\x00" in data:
        raise DatasetError(f"{path}: holds a zero byte at byte {data.index(0) + 1}: not a text file")
    return data, ""


def separator(line: str) -> str | None:
    """A row's separator: tab, comma or semicolon when it holds one (in that order), else None (spaces)."""
    return next((s for s in ("\t", ",", ";") if s in line), None)


def cells(line: str, sep: str | None) -> list[str]:
    """A row's cells, stripped of spaces and quotes."""
    parts = line.split(sep) if sep else line.split()
    return [p.strip().strip("\"'").strip() for p in parts]


@attrs.frozen(eq=False)
class Table:
    """The layout's columns read from a record: each role's values in SI (time s, displacement m, friction -,
    normal Pa or N), the file line of each row, and what was skipped or chosen (sentences)."""

    values: dict
    lines: np.ndarray
    notes: tuple


def read_table(path, text: str, layout: Layout) -> Table:
    """Read the layout's columns from a record's text; a one-line DatasetError naming the file, the line and
    the column at fault."""
    rows = text.split("\n")
    named = [c for c in layout.columns if c.position is None]
    notes = []
    if named:
        hi, sep, index = _header(path, rows, named)
        start = hi + 1
        if hi:
            notes.append(f"{hi} line{'s' * (hi != 1)} before the header skipped (line" +
                         ("s 1 to " if hi > 1 else " ") + f"{hi})")
    else:
        start, sep, index, hi = 0, None, {}, None
    index.update({c.role: c.position for c in layout.columns if c.position is not None})
    want = [index[c.role] for c in layout.columns]
    first = _first_data(rows, start, sep, want, own=not named)
    if first is not None and not named:
        sep = separator(rows[first])
    if first is None:
        raise DatasetError(f"{path}: no data rows" + (f" after the header (line {hi + 1})" if hi is not None else ""))
    skipped = [i + 1 for i in range(start, first) if rows[i].strip()]
    if skipped:
        notes.append(f"{len(skipped)} row{'s' * (len(skipped) != 1)} of text "
                     f"{'after the header' if hi is not None else 'before the data'} skipped (line"
                     f"{'s' * (len(skipped) != 1)} {skipped[0]}" + (f" to {skipped[-1]})" if len(skipped) > 1 else ")"))
    block, lines = _numbers(path, rows, first, sep, want, layout)
    values = {c.role: block[:, j] * c.factor for j, c in enumerate(layout.columns)}
    return Table(values=values, lines=lines, notes=tuple(notes))


def _header(path, rows: list[str], named: list[Column]) -> tuple[int, str | None, dict]:
    """(index of the header row, its separator, role -> column index) for the first row that names every
    column of ``named``; else the error naming what is missing in the row that names the most."""
    best = (-1, None, None)
    for i, row in enumerate(rows[:1000]):
        if not row.strip():
            continue
        sep = separator(row)
        found = [c.lower() for c in cells(row, sep)]
        have = {c.role: found.index(c.name.lower()) for c in named if c.name.lower() in found}
        if len(have) == len(named):
            return i, sep, have
        if len(have) > best[0]:
            best = (len(have), i, found)
    k, i, found = best
    if i is None:
        raise DatasetError(f"{path}: file is empty")
    missing = [c for c in named if c.name.lower() not in found]
    shown = ", ".join(repr(f) for f in found[:12]) + (", ..." if len(found) > 12 else "")
    return _no_header(path, i, missing, shown)


def _no_header(path, i: int, missing: list[Column], shown: str):
    what = ", ".join(f"{c.role}={c.name}" for c in missing)
    raise DatasetError(f"{path}: no header line names the column{'s' * (len(missing) > 1)} {what} given; "
                       f"line {i + 1} has {shown}")


def _number(cell: str) -> float:
    try:
        return float(cell)
    except ValueError:
        return math.nan


def _first_data(rows: list[str], start: int, sep, want: list[int], own: bool = False) -> int | None:
    """The first row from ``start`` whose wanted cells are all finite numbers (each row split by ``sep``, or by
    its own separator when ``own``)."""
    for i in range(start, len(rows)):
        if not rows[i].strip():
            continue
        c = cells(rows[i], separator(rows[i]) if own else sep)
        if len(c) > max(want) and all(math.isfinite(_number(c[j])) for j in want):
            return i
    return None


def _numbers(path, rows: list[str], first: int, sep, want: list[int], layout: Layout):
    """(rows x wanted columns of floats, the file line of each row) from row ``first`` on."""
    import pandas as pd

    body = "\n".join(rows[first:])
    order = np.argsort(want)
    try:
        frame = pd.read_csv(io.StringIO(body), sep=sep or r"\s+", header=None, usecols=sorted(set(want)),
                            dtype=float, engine="c", skip_blank_lines=True, skipinitialspace=True)
        block = frame.to_numpy()[:, np.argsort(order)] if len(set(want)) == len(want) else None
        ok = block is not None and bool(np.isfinite(block).all())
    except (ValueError, pd.errors.ParserError, pd.errors.EmptyDataError):
        ok, block = False, None
    lines = None
    if not ok or any(not r.strip() for r in "\n".join(rows[first:]).rstrip().split("\n")):
        lines = np.array([i + 1 for i in range(first, len(rows)) if rows[i].strip()], dtype=np.int64)
    if not ok:
        block = _slow(path, rows, lines, sep, want, layout)
    if lines is None:
        lines = np.arange(first + 1, first + 1 + len(block), dtype=np.int64)
    return block, lines


def _slow(path, rows, lines, sep, want, layout: Layout) -> np.ndarray:
    """The wanted cells of every row, read one row at a time (what the fast reader could not read); a
    one-line error for the first row whose wanted cells are not all finite numbers."""
    out = np.empty((len(lines), len(want)))
    for k, no in enumerate(lines):
        c = cells(rows[no - 1], sep)
        for m, (col, j) in enumerate(zip(layout.columns, want)):
            if j >= len(c):
                raise DatasetError(f"{path}: line {no}: {len(c)} column{'s' * (len(c) != 1)}, no column {j + 1} "
                                   f"for {col.role}={col.name}")
            out[k, m] = _number(c[j])
            if not math.isfinite(out[k, m]):
                raise DatasetError(f"{path}: line {no}: {col.role}={col.name}: {c[j][:40]!r} is not a finite number")
    return out
