"""Reading a dataset's numeric CSV: header row, comments '#', one-line errors naming file, line and column."""
from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np

from ..core.errors import DatasetError
from ..core.files import MAX_CSV_BYTES, read_bytes, read_text


def read_csv(csv: Path) -> dict[str, np.ndarray]:
    """Read a numeric CSV with a header row into float arrays; one-line errors on bad content.
    The CSV must lie in its folder once links are resolved (see io.read_bytes)."""
    import warnings

    import pandas as pd

    try:
        text = read_bytes(csv, MAX_CSV_BYTES, within=Path(csv).parent).decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise DatasetError(f"{csv}: CSV does not parse: not UTF-8 text (byte {exc.start + 1})") from None
    try:
        with warnings.catch_warnings():
            # more fields in every row than in the header: pandas would shift the columns silently
            warnings.simplefilter("error", pd.errors.ParserWarning)
            df = pd.read_csv(io.StringIO(text), comment="#", skipinitialspace=True, index_col=False, dtype=str,
                             keep_default_na=False)
    except pd.errors.EmptyDataError:
        raise DatasetError(f"{csv}: file is empty") from None
    except pd.errors.ParserWarning:
        raise DatasetError(f"{csv}: CSV does not parse: data rows have more fields than the header") from None
    except (pd.errors.ParserError, UnicodeError, ValueError, OSError) as exc:
        first = (str(exc).splitlines() or [type(exc).__name__])[0]
        raise DatasetError(f"{csv}: CSV does not parse: {first}") from None
    names = [str(c).strip() for c in df.columns]
    header = _header_names(text)
    for i, name in enumerate(header if header is not None else names):
        if not name:
            raise DatasetError(f"{csv}: header column {i + 1} has no name (a stray comma?)")
        if any(sep in name for sep in (";", "\t")):
            raise DatasetError(f"{csv}: header {name!r} looks ;- or tab-separated; write comma-separated values")
    if header is not None:
        dup = sorted({n for n in header if header.count(n) > 1})
        if dup:
            raise DatasetError(f"{csv}: column {dup[0]!r} appears more than once in the header")
    if len(df) == 0:
        raise DatasetError(f"{csv}: no data rows")
    out = {}
    for col, name in zip(df.columns, names):
        text = df[col]
        values = np.array([_number(x) for x in text], dtype=float)
        bad = np.nonzero(~np.isfinite(values))[0]
        if bad.size:
            i = int(bad[0])
            raise DatasetError(f"{csv}: column {name!r} line {_line_of_row(csv, i)}: {text.iloc[i]!r} "
                               "is not a finite number")
        out[name] = values
    return out


def _number(text) -> float:
    """A CSV cell as a float (correctly rounded, like Python's float), NaN if it is not a number."""
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def _header_names(text: str) -> list[str] | None:
    """Column names as written in the header line (pandas renames duplicates), or None if unreadable."""
    import csv as csvmod

    try:
        lines = text.splitlines(keepends=True)
        rows = (r for r in csvmod.reader(line for line in lines if line.strip() and not line.lstrip().startswith("#")))
        return [c.strip() for c in next(rows)]
    except (csvmod.Error, StopIteration):
        return None


def _line_of_row(csv: Path, row: int) -> int:
    """1-based line number in the file of data row ``row`` (0-based, after header and comments)."""
    try:
        lines = read_text(csv, MAX_CSV_BYTES).splitlines()
    except DatasetError:
        return 0
    data = [i for i, line in enumerate(lines) if line.strip() and not line.lstrip().startswith("#")]
    return data[row + 1] + 1 if row + 1 < len(data) else len(lines)
