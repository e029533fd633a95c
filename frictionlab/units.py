"""Units at the edges: quantity strings such as "46 g" or "500 us" become SI floats.

pint is imported lazily, only when a string has to be parsed. Inside frictionlab every
number is a plain float in SI units (angles in radians, spin in rad/s).
"""
from __future__ import annotations

import functools
import math

from .errors import UnitError

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


@functools.cache
def _registry():
    import pint

    return pint.UnitRegistry(autoconvert_offset_to_baseunit=True)


def _target(unit: str):
    ureg = _registry()
    return ureg.Quantity(1.0, unit) if unit else ureg.Quantity(1.0)


def unit_factor(unit: str, si_unit: str, where: str) -> float:
    """Factor that converts a value in ``unit`` to ``si_unit``; ``where`` names the field."""
    ureg = _registry()
    try:
        q = ureg.Quantity(1.0, unit.strip()) if unit.strip() else ureg.Quantity(1.0)
    except Exception:
        raise UnitError(f"{where}: unknown unit {unit!r}") from None
    target = _target(si_unit)
    if q.dimensionality != target.dimensionality:
        raise UnitError(
            f"{where}: unit {unit!r} is {_dim(q)}, expected {_dim(target)} (like {si_unit or 'a plain number'!r})"
        )
    _check_angle(q, target, repr(unit), si_unit, where)
    factor = float(q.to(target.units).magnitude)
    if not (math.isfinite(factor) and factor > 0):
        raise UnitError(f"{where}: unit {unit!r} does not convert to {si_unit or 'a plain number'!r}")
    return factor


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
        out = float(value)
    elif isinstance(value, str):
        ureg = _registry()
        try:
            q = ureg.Quantity(value.strip())
        except Exception:
            raise UnitError(f"{where}: cannot read quantity {value!r}") from None
        if not hasattr(q, "dimensionality"):  # pint returns a plain number for "30"
            q = ureg.Quantity(float(q))
        if si_unit and q.unitless:
            raise UnitError(f"{where}: {value!r} has no unit; write it like '{value.strip()} {si_unit}'")
        target = _target(si_unit)
        if q.dimensionality != target.dimensionality or q.dimensionality != target.dimensionality:
            raise UnitError(
                f"{where}: {value!r} is {_dim(q)}, expected {_dim(target)} (like '1 {si_unit}')"
                if si_unit
                else f"{where}: {value!r} should be a plain number"
            )
        _check_angle(q, target, repr(value), si_unit, where)
        out = float(q.to(target.units).magnitude)
    else:
        raise UnitError(f"{where}: expected a quantity string like '1 {si_unit}', got {type(value).__name__}")
    if not math.isfinite(out):
        raise UnitError(f"{where}: {value!r} is not finite")
    return out


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
