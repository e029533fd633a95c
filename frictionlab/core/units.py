"""Units at the edges: quantity strings such as "46 g" or "500 us" become SI floats.

pint is imported lazily, only when a string has to be parsed in a unit outside ``KNOWN`` (the units
laboratory files and scenes write most, whose factors are pint's own). Inside frictionlab every
number is a plain float in SI units (angles in radians, spin in rad/s).
"""
from __future__ import annotations

import functools
import math
import re

from .errors import ParameterError, UnitError

#: Limits checked on a quantity string before pint evaluates it (pint computes integer powers
#: exactly, so "9**9**9 g" would never finish, and "10**400 g" overflows a float).
MAX_TEXT = 200  # characters in a quantity or unit string
MAX_POWER = 12  # largest |exponent| after ** or ^ (m^3, s^-2 ... need far less)
MAX_LITERAL = 1e300  # largest number written in a quantity string
#: Accepted size of a value once converted to SI: |x| in [MIN_SI, MAX_SI], or exactly 0.
#: No physical input of frictionlab comes near these bounds (kg, m, s, Pa, N/m ...), and a
#: product of three such values stays finite, so a scene built from them never overflows.
MAX_SI = 1e100
MIN_SI = 1e-100

#: Minus signs other than the ASCII hyphen-minus that a quantity may hold, read as "-": the minus sign U+2212
#: (what word processors and PDFs write), the dashes U+2012-U+2015 and the small and fullwidth hyphen-minus.
MINUS_SIGNS = "\u2212\u2012\u2013\u2014\u2015\ufe63\uff0d"
_MINUS = str.maketrans(dict.fromkeys(MINUS_SIGNS, "-"))
_POWER = re.compile(r"\*\*|\^")
_EXPONENT = re.compile(r"\s*(\(\s*[-+]?\s*\d+(?:\.\d*)?\s*\)|[-+]?\s*\d+(?:\.\d*)?)(?![\d.eE])")
_LITERAL = re.compile(r"(?<![A-Za-z_\d.])(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")

#: SI unit string for each kind of quantity the project reads.
SI = {
    "mass": "kg",
    "length": "m",
    "area": "m^2",
    "time": "s",
    "velocity": "m/s",
    "angular_velocity": "rad/s",
    "angle": "rad",
    "force": "N",
    "dimensionless": "",
}


#: For each SI unit the project reads, the factor of each common unit to it, exactly as pint converts it (a
#: value v in one of them is v * factor in SI, to the last bit: tests/test_units.py checks every pair against pint).
#: Reading these needs no unit registry: importing pint and building its registry costs about a third of a CPU
#: second a process. Every other unit is pint's to read, and to refuse.
KNOWN = {
    "kg": {"kg": 1.0, "g": 1e-3, "mg": 1e-6},
    "m": {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "um": 1e-6, "nm": 1e-9},
    "s": {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9},
    "m/s": {"m/s": 1.0, "mm/s": 1e-3, "um/s": 1e-6, "nm/s": 1e-9},
    "m^2": {"m^2": 1.0, "cm^2": 1e-4, "mm^2": 1e-6, "um^2": 1e-12},
    "rad": {"rad": 1.0, "deg": math.pi / 180},
    "rad/s": {"rad/s": 1.0, "rpm": math.pi / 30, "deg/s": math.pi / 180},
    "N": {"N": 1.0, "kN": 1e3, "mN": 1e-3},
    "Pa": {"Pa": 1.0, "kPa": 1e3, "MPa": 1e6, "GPa": 1e9},
    "Pa s": {"Pa s": 1.0, "mPa s": 1e-3},
    "Pa s/m": {"Pa s/m": 1.0},
    "1/m": {"1/m": 1.0, "1/mm": 1e3, "1/um": 1e6},
    "m^2/m": {"m^2/m": 1.0, "mm^2/m": 1e-6},
    "s/m": {"s/m": 1.0},
    "": {"": 1.0},
}
#: A quantity string of one number and a unit: the number as Python reads it, then the unit.
_QUANTITY = re.compile(r"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*)")


@functools.cache
def _registry():
    import pint

    return pint.UnitRegistry(autoconvert_offset_to_baseunit=True)


def _target(unit: str):
    ureg = _registry()
    return ureg.Quantity(1.0, unit) if unit else ureg.Quantity(1.0)


def check_text(text: str, where: str) -> str:
    """Refuse a quantity or unit string pint could choke on, before pint sees it: longer than
    MAX_TEXT, control characters, a power that is not a plain number of at most MAX_POWER, a
    chained power (a**b**c), a number beyond MAX_LITERAL or one that underflows to 0. Returns the text
    stripped, each of MINUS_SIGNS made "-"."""
    shown = text if len(text) <= 40 else text[:37] + "..."
    if len(text) > MAX_TEXT:
        raise UnitError(f"{where}: {shown!r} is {len(text)} characters long; a quantity has at most {MAX_TEXT}")
    if not text.isprintable():
        odd = next(c for c in text if not c.isprintable())
        raise UnitError(f"{where}: {shown!r} holds control characters or odd spaces (U+{ord(odd):04X}); "
                        "write a number and its unit with plain spaces")
    text = text.translate(_MINUS)
    last_end = None
    for m in _POWER.finditer(text):
        if (last_end is not None and not text[last_end:m.start()].strip()) or _powered_group(text, m.start()):
            raise UnitError(f"{where}: {shown!r}: a power of a power is not accepted; write the exponent as one number")
        e = _EXPONENT.match(text, m.end())
        if e is None:
            raise UnitError(f"{where}: {shown!r}: the exponent after {m.group()!r} must be a plain number "
                            f"between -{MAX_POWER} and {MAX_POWER}")
        value = float(re.sub(r"[\s()]", "", e.group(1)))
        if abs(value) > MAX_POWER:
            raise UnitError(f"{where}: {shown!r}: exponent {value:g} is beyond the accepted +/-{MAX_POWER}")
        last_end = e.end()
    for m in _LITERAL.finditer(text):
        value = float(m.group())
        if not (math.isfinite(value) and value <= MAX_LITERAL):
            raise UnitError(f"{where}: {shown!r}: the number {m.group()[:20]}{'...' * (len(m.group()) > 20)} "
                            f"is beyond the accepted magnitude {MAX_LITERAL:g}")
        if value == 0 and re.search(r"[1-9]", m.group(1)):
            raise UnitError(f"{where}: {shown!r}: the number {m.group()} underflows to 0")
    return text.strip()


#: A number and what stands before it, in a quantity or unit string: a number after another number or a unit with
#: nothing but spaces between them is multiplied by pint ("1 810 000 Pa s/m" is 0, "2 3 Pa s/m" is 6).
_BEFORE_OPERATOR = re.compile(r"(\*|/|\^)[\s(+-]*$")
_LEADING = re.compile(r"\s*[-+]?(?:(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|(?:inf(?:inity)?|nan)\b)", re.IGNORECASE)


def check_one_number(text: str, where: str, shown=None, quantity: bool = True) -> None:
    """Refuse a quantity string (``quantity``) that does not start with a number, and a quantity or unit string
    in which a number follows another number or a unit with only spaces between them (pint would multiply
    them): a number after the first is accepted only after an operator (``*``, ``/``, ``**``, ``^``), or as
    the 1 of "1/m". ``text`` as ``check_text`` returns it; ``shown`` as given."""
    shown = text if shown is None else shown
    lead = _LEADING.match(text)
    if quantity and lead is None:
        raise UnitError(f"{where}: {shown!r} does not start with a number; write one number and its unit, "
                        "like '1.5 m/s'")
    prev = lead.group().strip() if lead else ""
    for m in _LITERAL.finditer(text, lead.end() if lead else 0):
        before = text[:m.start()]
        if before.strip() and not _BEFORE_OPERATOR.search(before) \
                and not (m.group() == "1" and text[m.end():].lstrip().startswith("/")):  # "2000 1/m"
            comma = "," in before[-2:]
            what = "one number and its unit" if quantity else "a unit with no number but its powers (m^2, 1/s)"
            raise UnitError(f"{where}: {shown!r} holds more than one number ({prev or before.split()[-1]} then "
                            f"{m.group()}, which would be multiplied); write {what}"
                            + (" (a decimal point, not a comma: 1.5, not 1,5)" if comma else
                               ", without spaces or separators inside a number (1810000 or 1.81e6, not 1 810 000)"
                               if quantity else ""))
        prev = m.group()


def leading_number(text: str) -> float | None:
    """The number a quantity string starts with (its sign included), or None."""
    m = _LEADING.match(text.translate(_MINUS))
    return float(m.group()) if m else None


def _powered_group(text: str, op: int) -> bool:
    """True if the power operator at ``op`` applies to a parenthesized group that holds a power."""
    base = text[:op].rstrip()
    if not base.endswith(")"):
        return False
    depth = 0
    for i in range(len(base) - 1, -1, -1):
        depth += {")": 1, "(": -1}.get(base[i], 0)
        if depth == 0:
            return bool(_POWER.search(base[i:]))
    return True  # unbalanced: pint would refuse it anyway


def check_magnitude(value: float, shown, where: str, si_unit: str = "") -> float:
    """``value`` (SI) unless it is not finite or its size is outside [MIN_SI, MAX_SI] (0 passes)."""
    if not math.isfinite(value):
        raise UnitError(f"{where}: {shown!r} is not finite")
    if abs(value) > MAX_SI or 0 < abs(value) < MIN_SI:
        raise UnitError(f"{where}: {shown!r} is {value:.3g} {si_unit or ''}".rstrip()
                        + f" in SI units; accepted magnitudes are {MIN_SI:g} to {MAX_SI:g} (or 0)")
    return value


def unit_factor(unit: str, si_unit: str, where: str) -> float:
    """Factor that converts a value in ``unit`` to ``si_unit``; ``where`` names the field."""
    shown, unit = unit, check_text(unit, where)
    check_one_number(unit, where, shown, quantity=False)
    known = KNOWN.get(si_unit, {}).get(unit)
    if known is not None:
        return known
    ureg = _registry()
    try:
        q = ureg.Quantity(1.0, unit) if unit else ureg.Quantity(1.0)
    except Exception:
        raise UnitError(f"{where}: unknown unit {unit!r}") from None
    if not hasattr(q, "dimensionality"):
        raise UnitError(f"{where}: unknown unit {unit!r}")
    target = _target(si_unit)
    if q.dimensionality != target.dimensionality:
        raise UnitError(
            f"{where}: unit {unit!r} is {_dim(q)}, expected {_dim(target)} (like {si_unit or 'a plain number'!r})"
        )
    _check_angle(q, target, repr(unit), si_unit, where)
    try:
        factor = float(q.to(target.units).magnitude)
    except (OverflowError, ValueError, ArithmeticError):
        factor = math.nan
    if not (math.isfinite(factor) and factor > 0):
        raise UnitError(f"{where}: unit {unit!r} does not convert to {si_unit or 'a plain number'!r}")
    return check_magnitude(factor, unit, f"{where} (unit factor)", si_unit)


def to_si(value, si_unit: str, where: str) -> float:
    """Convert a quantity string (``"46 g"``) or a bare number to a float in ``si_unit``.

    A bare number is accepted only for dimensionless quantities: a dimensional value
    must say its unit, so that "0.046" can never be misread as grams.
    """
    if isinstance(value, bool):
        raise UnitError(f"{where}: expected a quantity, got {value!r}")
    if isinstance(value, (int, float)):
        if si_unit:
            raise UnitError(f"{where}: {value!r} has no unit; write it as a string like '{value} {si_unit}'")
        try:
            out = float(value)
        except OverflowError:
            out = math.inf
    elif isinstance(value, str):
        text = check_text(value, where)
        check_one_number(text, where, value)
        m = _QUANTITY.fullmatch(text)
        known = KNOWN.get(si_unit, {}).get(m[2]) if m else None
        if known is not None:
            return check_magnitude(float(m[1]) * known, value, where, si_unit)
        ureg = _registry()
        try:
            q = ureg.Quantity(text)
            if not hasattr(q, "dimensionality"):  # pint returns a plain number for "30"
                q = ureg.Quantity(float(q))
        except Exception:
            raise UnitError(f"{where}: cannot read quantity {value!r}") from None
        if si_unit and q.unitless:
            raise UnitError(f"{where}: {value!r} has no unit; write it like '{value.strip()} {si_unit}'")
        target = _target(si_unit)
        if q.dimensionality != target.dimensionality:
            raise UnitError(
                f"{where}: {value!r} is {_dim(q)}, expected {_dim(target)} (like '1 {si_unit}')"
                if si_unit
                else f"{where}: {value!r} should be a plain number"
            )
        _check_angle(q, target, repr(value), si_unit, where)
        try:
            out = float(q.to(target.units).magnitude)
        except (OverflowError, ValueError, ArithmeticError):
            out = math.inf
    else:
        raise UnitError(f"{where}: expected a quantity string like '1 {si_unit}', got {type(value).__name__}")
    return check_magnitude(out, value, where, si_unit)


def _angle_power(q) -> float:
    """Power of the radian in a quantity's root units (pint counts angles as dimensionless)."""
    _, root = _registry().get_root_units(q.units)
    return dict(root._units).get("radian", 0)


def _check_angle(q, target, shown: str, si_unit: str, where: str) -> None:
    """Angles are dimensionless to pint, so 1 Hz would convert to 1 rad/s and 30 deg to 0.52:
    refuse a value whose angle part differs from the target's (a factor 2 pi or 57 goes unseen)."""
    given, wanted = _angle_power(q), _angle_power(target)
    if given == wanted:
        return
    if wanted and si_unit == "rad/s":
        raise UnitError(f"{where}: {shown} has no angle unit; write it like 'rad/s', 'rpm' or 'deg/s' "
                        "(Hz and 1/s are ambiguous: read as rad/s they are off by 2 pi)")
    if wanted:
        raise UnitError(f"{where}: {shown} has no angle unit; write it like 'rad' or 'deg'")
    raise UnitError(f"{where}: {shown} is an angle, expected {_dim(target)} (like {si_unit or 'a plain number'!r})")


def _dim(q) -> str:
    d = str(q.dimensionality)
    return "dimensionless" if d == "dimensionless" else d


#: A time column is refused when its last time exceeds TIME_SPAN_MAX times the scene's duration (the
#: scene ends long before the data do) or falls below TIME_SPAN_MIN times it (the data would cover
#: less than 0.2% of the scene). A unit slip by a factor 1000 or more (s for ms, s for us, ns for
#: us) always lands outside, while data that stop early or run on a little pass.
TIME_SPAN_MAX = 20.0
TIME_SPAN_MIN = 1 / 500
_TIME_UNITS = (("ns", 1e-9), ("us", 1e-6), ("ms", 1e-3), ("s", 1.0))


def check_time_scale(t_last: float, duration: float, unit: str, where: str, duration_field: str) -> None:
    """Refuse a time column whose span does not fit the scene's duration (an error, not a warning:
    a time unit off by 1e3 or 1e6 fits confidently and wrongly). ``t_last`` and ``duration`` in s."""
    if not (t_last > 0 and duration > 0):
        return
    ratio = t_last / duration
    if TIME_SPAN_MIN <= ratio <= TIME_SPAN_MAX:
        return
    raw = t_last / unit_factor(unit, "s", where)
    guess, factor = min(_TIME_UNITS, key=lambda u: abs(math.log(raw * u[1] / duration)))
    fits = TIME_SPAN_MIN <= raw * factor / duration <= TIME_SPAN_MAX and guess != unit.strip()
    raise UnitError(f"{where}: the last time is {raw:g} {unit}, {ratio:.3g} times {duration_field} "
                    f"({duration:g} s): declared unit {unit!r} is implausible"
                    + (f"; the values look like {guess}" if fits else "")
                    + f" (accepted: the last time within {TIME_SPAN_MIN:g} to {TIME_SPAN_MAX:g} times the "
                    "scene's duration)")


#: What the Python API accepts wherever a value is given, for error messages.
FORMS = "a number in SI, a quantity string such as '{example}' or a pint Quantity"


def is_quantity(value) -> bool:
    """True for a pint Quantity (of any unit registry), told by its interface, not its class."""
    return hasattr(value, "magnitude") and hasattr(value, "units") and hasattr(value, "dimensionality")


def as_si(value, si_unit: str, where: str) -> float:
    """A value of the Python API in SI: an SI number as it is, a quantity string (``"1.5e6 Pa s/m"``) or a
    pint Quantity converted from its unit (finite, within the accepted magnitudes); a boolean is a
    ParameterError, anything else or a unit of the wrong dimension a UnitError, each naming ``where`` (the
    parameter) and ``si_unit`` (the unit expected)."""
    import numbers

    example = f"1 {si_unit}" if si_unit else "0.3"
    if isinstance(value, bool) or (hasattr(value, "dtype") and getattr(value.dtype, "kind", "") == "b"):
        raise ParameterError(f"{where} = {value!r} is a boolean, not a number; expected "
                             f"{FORMS.format(example=example)}")
    if isinstance(value, numbers.Real):
        return float(value)  # SI as given: the caller checks it against the parameter's bounds
    if isinstance(value, str):
        return to_si(value, si_unit, where)
    if is_quantity(value):
        try:
            magnitude = float(value.magnitude)
        except (TypeError, ValueError):
            raise UnitError(f"{where}: {value!r}: expected one value, got {type(value.magnitude).__name__}") from None
        unit = str(value.units)
        if unit == "dimensionless":
            unit = ""
        factor = unit_factor(unit, si_unit, f"{where} ({value!r})")
        return check_magnitude(magnitude * factor, value, where, si_unit)
    raise UnitError(f"{where}: expected {FORMS.format(example=example)}, got {type(value).__name__} {value!r:.60}")


def as_range(value, si_unit: str, where: str) -> tuple[float, ...]:
    """Bounds (lower, upper) or (lower, upper, start) in SI from ``"low:high[:start]"`` (the command line's
    form) or a tuple or list of two or three values, each in any form ``as_si`` reads; lower < upper and the
    start within them, or a UnitError naming ``where``."""
    if isinstance(value, str):
        parts = [p.strip() for p in value.split(":")]
        if len(parts) not in (2, 3) or not all(parts):
            raise UnitError(f"{where}: {value!r}: expected 'LOWER:UPPER' or 'LOWER:UPPER:START', each with its "
                            f"unit (like '1 {si_unit}:2 {si_unit}')")
        items = parts
    elif isinstance(value, (tuple, list)) and len(value) in (2, 3):
        items = list(value)
    else:
        raise UnitError(f"{where}: expected bounds as 'LOWER:UPPER[:START]' or a tuple (lower, upper[, start]) of "
                        f"{FORMS.format(example=f'1 {si_unit}' if si_unit else '0.3')}, got {value!r:.60}")
    out = tuple(as_si(x, si_unit, where) for x in items)
    if not out[0] < out[1]:
        raise ParameterError(f"{where}: lower bound {items[0]!r} must be below upper {items[1]!r}")
    if len(out) == 3 and not out[0] <= out[2] <= out[1]:
        raise ParameterError(f"{where}: start {items[2]!r} is outside its bounds [{items[0]}, {items[1]}]")
    return out
