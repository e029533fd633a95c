"""Reading a dataset's numeric CSV: header row, comments '#', one-line errors naming file, line and column."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..core.errors import DatasetError
from ..core.files import MAX_CSV_BYTES, read_bytes, read_text


def read_csv(csv: Path, text: str | None = None) -> dict[str, np.ndarray]:
    """Read a numeric CSV with a header row into float arrays; one-line errors on bad content.
    '#' starts a comment (to the end of its line); blank lines are skipped; cells may be quoted and
    padded with spaces. The CSV must lie in its folder once links are resolved (see io.read_bytes).
    ``text``: the file's content, already read (``csv`` then only names it)."""
    if text is None:
        try:
            text = read_bytes(csv, MAX_CSV_BYTES, within=Path(csv).parent).decode("utf-8-sig")
        except UnicodeDecodeError as exc:
            raise DatasetError(f"{csv}: CSV does not parse: not UTF-8 text (byte {exc.start + 1})") from None
    plain = _plain(text)
    if plain is not None:
        header, block = plain
        _check_header(csv, header)
        return {name: np.ascontiguousarray(block[:, j]) for j, name in enumerate(header)}
    rows = _rows(csv, text)
    if not rows:
        raise DatasetError(f"{csv}: file is empty")
    _, header = rows[0]
    _check_header(csv, header)
    if len(rows) == 1:
        raise DatasetError(f"{csv}: no data rows")
    for line, cells in rows[1:]:
        if len(cells) > len(header):
            raise DatasetError(f"{csv}: CSV does not parse: data rows have more fields than the header (line "
                               f"{line}: {len(cells)} fields, the header {len(header)})")
    out = {}
    for j, name in enumerate(header):
        cells = [c[j] if j < len(c) else "" for _, c in rows[1:]]
        values = np.array([_number(x) for x in cells], dtype=float)
        bad = np.nonzero(~np.isfinite(values))[0]
        if bad.size:
            i = int(bad[0])
            raise DatasetError(f"{csv}: column {name!r} line {rows[1 + i][0]}: {cells[i]!r} is not a finite number")
        out[name] = values
    return out


def _check_header(csv: Path, header: list[str]) -> None:
    for i, name in enumerate(header):
        if not name:
            raise DatasetError(f"{csv}: header column {i + 1} has no name (a stray comma?)")
        if any(sep in name for sep in (";", "\t")):
            raise DatasetError(f"{csv}: header {name!r} looks ;- or tab-separated; write comma-separated values")
    dup = sorted({n for n in header if header.count(n) > 1})
    if dup:
        raise DatasetError(f"{csv}: column {dup[0]!r} appears more than once in the header")


def _plain(text: str) -> tuple[list[str], np.ndarray] | None:
    """(header, rows x columns of floats) of a CSV without quotes whose every data row (comments cut) has the
    header's number of cells, all finite numbers: what ``read_csv``'s general path reads from it, parsed in one
    call (numpy reads decimal text as float() does). None for anything else, which the general path reads or
    refuses with the line and column at fault."""
    if '"' in text:
        return None
    lines = text.splitlines()
    if "#" in text:
        lines = [line.split("#", 1)[0] for line in lines]
    lines = [line for line in lines if line.strip()]
    if len(lines) < 2:
        return None
    header = [c.strip() for c in lines[0].split(",")]
    cells = ",".join(lines[1:]).split(",")
    if len(cells) != len(header) * (len(lines) - 1):
        return None
    try:
        block = np.array(cells, dtype=float).reshape(len(lines) - 1, len(header))
    except ValueError:
        return None
    return (header, block) if np.isfinite(block).all() else None


def _rows(csv: Path, text: str) -> list[tuple[int, list[str]]]:
    """(1-based line number, cells stripped of spaces) of each line that holds data after its comment is cut."""
    import csv as csvmod

    kept = [(n, line.split("#", 1)[0]) for n, line in enumerate(text.splitlines(), 1)]
    kept = [(n, line) for n, line in kept if line.strip()]
    out = []
    reader = csvmod.reader((line for _, line in kept), skipinitialspace=True, strict=True)  # one reader: a line each
    for i, (n, _) in enumerate(kept):
        try:
            cells = next(reader)
        except csvmod.Error as exc:
            raise DatasetError(f"{csv}: CSV does not parse: line {n}: {exc}") from None
        if reader.line_num != i + 1:  # a quoted cell ran on into the next line (which this row then took)
            raise DatasetError(f"{csv}: CSV does not parse: line {n}: a quoted cell is not closed on its line")
        out.append((n, [c.strip() for c in cells]))
    return out


def _number(text) -> float:
    """A CSV cell as a float (correctly rounded, like Python's float), NaN if it is not a number."""
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def _line_of_row(csv: Path, row: int) -> int:
    """1-based line number in the file of data row ``row`` (0-based, after header and comments); 0 if unreadable."""
    try:
        rows = _rows(csv, read_text(csv, MAX_CSV_BYTES))
    except DatasetError:
        return 0
    return rows[row + 1][0] if row + 1 < len(rows) else (rows[-1][0] if rows else 0)
