"""Units at the edge: how SI values are shown in reports, tables and figures."""
from __future__ import annotations

import math

#: Display unit and factor (display = SI * factor) per observable / series.
OBSERVABLE_UNITS = {
    "mu": ("-", 1.0),
    "omega": ("rpm", 60.0 / (2.0 * math.pi)),
    "theta": ("deg", 180.0 / math.pi),
    "v": ("m/s", 1.0),
    "u": ("m/s", 1.0),
    "force": ("N", 1.0),
    "A": ("mm^2", 1e6),
    "N": ("N", 1.0),
}

NAMES = {"omega": "spin omega", "theta": "rotation angle theta", "v": "velocity v", "u": "slip u",
         "force": "friction force F", "A": "contact area A", "N": "normal force N",
         "mu": "friction coefficient mu (spring force / N)"}


def unit(name: str) -> tuple[str, float]:
    """(display unit, factor) for an observable or series name; SI with factor 1 if unknown."""
    return OBSERVABLE_UNITS.get(name, ("SI", 1.0))


def time_unit(t_max: float) -> tuple[str, float]:
    """A time unit that keeps numbers readable for a record lasting t_max seconds."""
    if t_max < 2e-3:
        return "us", 1e6
    if t_max < 2.0:
        return "ms", 1e3
    return "s", 1.0


def fmt_time(t: float, ref: float | None = None) -> str:
    name, f = time_unit(ref if ref is not None else t)
    return f"{t * f:.4g} {name}"


def fmt(x, digits: int = 4) -> str:
    """A number for a table: '' for None/nan, fixed or scientific by size."""
    if x is None:
        return ""
    if isinstance(x, (int,)) and not isinstance(x, bool):
        return str(x)
    try:
        x = float(x)
    except (TypeError, ValueError):
        return str(x)
    if not math.isfinite(x):
        return "" if math.isnan(x) else ("inf" if x > 0 else "-inf")
    if x == 0:
        return "0"
    if 1e-3 <= abs(x) < 1e5:
        return f"{x:.{digits}g}"
    return f"{x:.{digits - 1}e}"


def fmt_value(value: float, err: float | None, unit_: str) -> str:
    """'1.234e+06 +/- 2.1e+04 Pa s/m' style."""
    u = f" {unit_}" if unit_ else ""
    if err is None:
        return f"{fmt(value)}{u}"
    return f"{fmt(value)} ± {fmt(err, 2)}{u}"


#: SI unit -> (display unit, factor, threshold): shown in the display unit when |value| < threshold.
_SMALL = {"m": ("um", 1e6, 1e-3), "m^2": ("mm^2", 1e6, 1e-2), "s": ("us", 1e6, 2e-3)}


def _scale(value: float | None, unit_: str) -> tuple[str, float]:
    """(display unit, factor) for a parameter of SI unit ``unit_`` and size ``value``."""
    if unit_ in _SMALL and value is not None and math.isfinite(value) and abs(value) < _SMALL[unit_][2]:
        return _SMALL[unit_][:2]
    return unit_, 1.0


def param_text(value: float, err: float | None, unit_: str) -> str:
    """A parameter with its error for a table, small lengths, areas and times in um, mm^2, us."""
    name, f = _scale(value, unit_)
    return fmt_value(value * f, None if err is None else err * f, name)


def interval_text(lo: float, hi: float, unit_: str, like: float | None = None) -> str:
    """'[lo, hi] unit', in the display unit that ``param_text`` uses for a value ``like``."""
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return ""
    name, f = _scale(like if like is not None else hi, unit_)
    return f"[{fmt(lo * f)}, {fmt(hi * f)}]" + (f" {name}" if name else "")
