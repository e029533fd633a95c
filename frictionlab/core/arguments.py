"""Arguments of the Python API, checked as the command line checks them.

* A list argument given one string (or path, or object) is a list of that one item: ``datasets="x"``
  is ``["x"]``, never the characters of "x".
* A boolean is not a number (``True`` is not 1 m).
* A wrong type is a TypeError naming the parameter, raised at the call, never an AttributeError
  from deep inside.
"""
from __future__ import annotations

import numbers
import types


def as_items(value, where: str) -> list:
    """``value`` as a list: a list, tuple, set or generator is listed; a mapping is a TypeError naming
    ``where``; anything else (one string, path or dataset) is a list of that one item."""
    if isinstance(value, dict):
        raise TypeError(f"{where}: expected a name or a list of names, got a dict")
    if isinstance(value, (list, tuple, set, frozenset, types.GeneratorType)):
        return list(value)
    return [value]


def is_number(value) -> bool:
    """True for a real number that is not a boolean."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def check_type(value, types, where: str, expected: str):
    """``value`` if it is an instance of ``types``, else a TypeError naming ``where`` and what was expected."""
    if isinstance(value, bool) and bool not in (types if isinstance(types, tuple) else (types,)):
        raise TypeError(f"{where}: expected {expected}, got a boolean ({value!r})")
    if not isinstance(value, types):
        raise TypeError(f"{where}: expected {expected}, got {type(value).__name__} {value!r:.60}")
    return value
