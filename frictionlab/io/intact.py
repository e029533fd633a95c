"""A Dataset checked where it is used (fit, simulate, compare): still what loading made of it.

A Dataset's columns, noise and fixed values are a plain dict of arrays and dicts of floats, which code can change
after loading (a column shortened, scaled or made a list, a fixed value set to True). Loading validated them; each
use checks them again, in one pass over each array (linear in the samples, far below a fit's cost), and refuses a
change with a one-line DatasetError naming the use, the dataset and the field.
"""
from __future__ import annotations

import math
import numbers

import numpy as np

from ..core.errors import DatasetError, ParameterError
from ..core.units import MAX_SI

def check_intact(ds, where: str) -> None:
    """Refuse a Dataset ``ds`` changed after loading: every column a finite 1-D float array of one length, within
    the accepted magnitude (``units.MAX_SI``), the observable among them, the time never decreasing; every
    noise and fixed value a real number (finite, or NaN for a noise-free reconstruction's sigma)."""
    name = f"{where}: dataset '{ds.name}'"
    after = "(changed after loading? load the dataset again)"
    columns = ds.columns
    if not isinstance(columns, dict) or not columns:
        raise DatasetError(f"{name}: columns is {type(columns).__name__}, expected the dict of arrays loading made "
                           f"{after}")
    first = n = None
    for col, arr in columns.items():
        if not isinstance(arr, np.ndarray) or arr.dtype.kind != "f" or arr.ndim != 1:
            what = f"a {arr.ndim}-D {arr.dtype} array" if isinstance(arr, np.ndarray) else type(arr).__name__
            raise DatasetError(f"{name}: column {col!r} is {what}, expected a 1-D float array {after}")
        if first is None:
            first, n = col, arr.size
        elif arr.size != n:
            raise DatasetError(f"{name}: column {col!r} has {arr.size} values and column {first!r} {n}; the columns "
                               f"must have one length {after}")
        if arr.size and not -MAX_SI <= arr.min() <= arr.max() <= MAX_SI:  # min and max are NaN if any value is
            i = int(np.argmax(~(np.abs(arr) <= MAX_SI)))
            if not math.isfinite(arr[i]):
                raise DatasetError(f"{name}: column {col} holds a value that is not a finite number in row {i + 1} "
                                   f"{after}")
            raise DatasetError(f"{name}: column {col!r} value {i} is {arr[i]:.3g} in SI units, beyond the accepted "
                               f"magnitude {MAX_SI:g} {after}")
    if ds.observable not in columns:
        raise DatasetError(f"{name}: the observable {ds.observable!r} is no longer among its columns {after}")
    t = columns.get("t")
    if t is not None and n > 1 and not (t[1:] >= t[:-1]).all():  # a case resample repeats times
        i = int(np.argmax(~(t[1:] >= t[:-1]))) + 1
        raise DatasetError(f"{name}: column t must not decrease (row {i + 1}) {after}")
    for table, values in (("noise", ds.noise), ("fixed", ds.fixed)):
        if not isinstance(values, dict):
            raise DatasetError(f"{name}: {table} is {type(values).__name__}, expected a dict {after}")
        for key, v in values.items():
            ok = isinstance(v, numbers.Real) and not isinstance(v, (bool, np.bool_)) and (
                math.isfinite(v) or (table == "noise" and ds.noise_kind == "none" and math.isnan(v)))
            if not ok:
                error = ParameterError if table == "fixed" else DatasetError
                raise error(f"{name}: [{table}] {key} = {v!r:.40} is not a finite number in SI units {after}")
