"""Units at the edge: how SI values are shown in reports, tables and figures."""
from __future__ import annotations

import functools
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


def pyplot():
    """matplotlib.pyplot drawing off screen (Agg), with mathtext off: a label is shown as written,
    so a name or description holding '$' (a plugin named 'cost$\\frac$law') cannot be parsed as TeX; and glyphs
    unhinted (``text.hinting = "no_hinting"``: their outlines as designed, anti-aliased, as matplotlib's own tests
    draw text), which FreeType lays out in 0.55 to 0.75 of the time hinting takes (a 41-character label: 0.53
    against 0.96 ms), most of a report figure's text cost; the figures look the same at the report's DPI."""
    import matplotlib

    matplotlib.use("Agg", force=True)
    matplotlib.rcParams["text.parse_math"] = False
    matplotlib.rcParams["text.hinting"] = "no_hinting"
    import matplotlib.pyplot as plt

    return plt


def plain_log(axis) -> None:
    """Tick labels of a log ``axis`` (ax.xaxis, ax.yaxis, a colorbar's) in plain text (1e-05, 0.001, 100):
    matplotlib's default log labels are mathtext, which ``pyplot`` turns off (they would print as TeX)."""
    from matplotlib.ticker import LogFormatter

    axis.set_major_formatter(LogFormatter(labelOnlyBase=False))
    axis.set_minor_formatter(LogFormatter(labelOnlyBase=False, minor_thresholds=(1, 0.4)))


def unit(name: str) -> tuple[str, float]:
    """(display unit, factor) for an observable or series name; SI with factor 1 if unknown."""
    return OBSERVABLE_UNITS.get(name, ("SI", 1.0))


def time_unit(t_max: float) -> tuple[str, float]:
    """A time unit that keeps numbers readable for a record lasting t_max seconds."""
    if t_max < 2e-3:
        return "µs", 1e6
    if t_max < 2.0:
        return "ms", 1e3
    return "s", 1.0


def fmt_time(t: float, ref: float | None = None) -> str:
    name, f = time_unit(ref if ref is not None else t)
    return f"{t * f:.4g} {name}"


def fmt(x, digits: int = 4) -> str:
    """A number for a table with ``digits`` significant figures: '' for None/nan, fixed or scientific by size."""
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
    if 1e-3 <= abs(x) < 1e5:  # the same number of significant figures everywhere: 1.000, 12.50, 1234, 10090
        exp = math.floor(math.log10(abs(x)))
        if exp >= digits - 1:
            return f"{round(x, digits - 1 - exp):.0f}"
        return f"{x:#.{digits}g}".rstrip(".")
    return f"{x:.{digits - 1}e}"


def rounded(value: float, err: float | None) -> tuple[str, str]:
    """(value, error) as text, the error to two significant figures and the value to the same decimal
    place: (397.3, 11.2) -> ('397', '11'); (1.7851e6, 2.13e4) -> ('1.785e6', '0.021e6'). Without a finite,
    positive error the value has four significant figures and the error is ''."""
    if err is None or not (math.isfinite(err) and err > 0) or not math.isfinite(value):
        return fmt(value), ""
    last = math.floor(math.log10(err)) - 1  # the decimal place of the error's second significant figure
    top = math.floor(math.log10(abs(value))) if value else last
    if -3 <= max(top, last) < 5:  # plain decimals
        d = max(0, -last)
        return f"{round(value, -last):.{d}f}", f"{round(err, -last):.{d}f}"
    e = max(top, last + 1)  # one power of ten for both
    d = e - last
    return f"{value / 10**e:.{d}f}e{e}", f"{err / 10**e:.{d}f}e{e}"


def fmt_value(value: float, err: float | None, unit_: str) -> str:
    """'397 ± 11 µm': a value rounded to its standard error, with its unit."""
    u = f" {unit_}" if unit_ else ""
    v, e = rounded(value, err)
    return f"{v} ± {e}{u}" if e else f"{v}{u}"


#: How a unit string is written for people (pint reads the left, a reader the right).
_PRETTY = {"um": "µm", "us": "µs", "1/um": "1/µm", "um/s": "µm/s"}


@functools.cache
def _shown(unit_: str, shown: str) -> tuple[str, float]:
    """(unit as printed, factor: shown = SI * factor) of a quantity of SI unit ``unit_`` shown in ``shown``."""
    if not shown or shown == unit_:
        return unit_, 1.0
    from .units import unit_factor

    return _PRETTY.get(shown, shown), 1.0 / unit_factor(shown, unit_, f"display unit {shown!r}")


def param_text(value: float, err: float | None, unit_: str, shown: str = "") -> str:
    """A parameter with its error for a table, in its display unit ``shown`` (the law's or the scene
    quantity's declared unit; '' keeps the SI unit): one unit per quantity, whatever the value's size."""
    name, f = _shown(unit_, shown)
    return fmt_value(value * f, None if err is None else err * f, name)


def param_cells(value: float, err: float | None, unit_: str, shown: str = "") -> tuple[str, str, str]:
    """(value, standard error, unit) as table cells, in the display unit ``param_text`` uses."""
    name, f = _shown(unit_, shown)
    v, e = rounded(value * f, None if err is None else err * f)
    return v, e, name


def interval_text(lo: float, hi: float, unit_: str, shown: str = "") -> str:
    """'[lo, hi] unit', in the display unit that ``param_text`` uses."""
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return ""
    name, f = _shown(unit_, shown)
    return f"[{fmt(lo * f)}, {fmt(hi * f)}]" + (f" {name}" if name else "")


#: SI unit -> (display unit, factor, threshold): a scene value is shown in the display unit when |value| < threshold.
_SMALL = {"m": ("µm", 1e6, 1e-3), "m^2": ("mm^2", 1e6, 1e-2), "s": ("µs", 1e6, 2e-3)}


def _scale(value: float | None, unit_: str) -> tuple[str, float]:
    """(display unit, factor) for a scene value of SI unit ``unit_`` and size ``value``."""
    if unit_ in _SMALL and value is not None and math.isfinite(value) and abs(value) < _SMALL[unit_][2]:
        return _SMALL[unit_][:2]
    return unit_, 1.0


#: SI unit of scene fields by name (for describing a scene in units a person reads).
SCENE_FIELD_UNITS = {
    "mass": "kg", "u0": "m/s", "duration": "s", "radius": "m", "omega0": "rad/s", "incline": "rad",
    "peak": "m^2", "area": "m^2", "initial": "m^2", "rate": "m^2/m", "contact_time": "s", "impulse": "N*s",
    "coefficient": "N/m^3", "stiffness": "N/m", "damping": "N*s/m", "reference_speed": "m/s",
    "slope": "s/m", "modulus": "Pa", "normal_speed": "m/s", "impact_speed": "m/s", "incidence": "rad",
}
#: Owner class -> SI unit of its 'value' field.
VALUE_UNITS = {"WeightNormal": "N", "ConstantNormal": "N"}
#: Owner class -> SI units of fields whose name means another unit elsewhere (a spring-slider's stiffness).
OWNER_FIELD_UNITS = {"SpringLoad": {"stiffness": "1/m", "times": "s", "velocities": "m/s", "mass": "kg"}}


def quantity_text(value: float, unit_: str) -> str:
    """A scene value for people: g, mm, deg, rpm, and µm/mm^2/µs where small; 4 significant figures."""
    value = float(value)
    if unit_ == "kg" and abs(value) < 1:
        value, unit_ = value * 1e3, "g"
    elif unit_ == "rad":
        value, unit_ = math.degrees(value), "deg"
    elif unit_ == "rad/s":
        value, unit_ = value * 60 / (2 * math.pi), "rpm"
    elif unit_ == "m" and 1e-3 <= abs(value) < 1:
        value, unit_ = value * 1e3, "mm"
    elif unit_ == "m/s" and 0 < abs(value) < 1e-3:  # a load point's velocity
        value, unit_ = value * 1e6, "um/s"
    elif unit_ == "1/m":  # a rate-and-state stiffness per unit normal stress reads per micrometre
        value, unit_ = value * 1e-6, "1/um"
    else:
        name, f = _scale(value, unit_)
        value, unit_ = value * f, name
    return f"{value:.4g}" + (f" {unit_}" if unit_ else "")


def describe(obj, unit_: str = "") -> list[str]:
    """Lines describing a scene (or an attrs object, a dict, a number) in units a person reads: the
    first line is the value or the type, the others (indented) its fields; None fields left out."""
    import attrs
    import numpy as np

    if isinstance(obj, (int, float, np.floating, np.integer)) and not isinstance(obj, bool):
        return [quantity_text(obj, unit_)]
    if isinstance(obj, (tuple, list)) and obj and unit_ and all(isinstance(v, (int, float)) for v in obj):
        return [", ".join(quantity_text(v, unit_) for v in obj)]
    if isinstance(obj, (frozenset, set, tuple, list)):
        return [", ".join(sorted(map(str, obj))) or "none"]
    if isinstance(obj, np.ndarray):
        return [f"{obj.size} values from a column"]
    if type(obj).__name__ == "SpeedLaw":  # value (at a reference speed) scaled with the impact speed
        if obj.reference_speed is None:
            return [quantity_text(obj.value, unit_)]
        ref = quantity_text(obj.reference_speed, "m/s")
        text = f"{quantity_text(obj.value, unit_)} at normal speed {ref}"
        if obj.exponent:
            text += f", scaled by (v_n / {ref})^{obj.exponent:g}"
        if obj.slope:
            text += f", {obj.slope:+g} per m/s of v_n above {ref}"
        return [text]
    if attrs.has(type(obj)):
        head, items = type(obj).__name__, [(f.name, getattr(obj, f.name)) for f in attrs.fields(type(obj))]
    elif isinstance(obj, dict):
        head, items = obj.get("model", "table"), [(k, v) for k, v in obj.items() if k != "model"]
    else:
        return [str(obj)]
    lines = [str(head)]
    for name, value in items:
        if value is None or name == "kind":
            continue
        u = VALUE_UNITS.get(head, "") if name == "value" else SCENE_FIELD_UNITS.get(name, "")
        u = OWNER_FIELD_UNITS.get(head, {}).get(name, u)
        sub = describe(value, u)
        lines.append(f"  {name}: {sub[0]}")
        lines += ["  " + x for x in sub[1:]]
    return lines


# -- what a result draws in a notebook (the .plot() methods) ---------------------------------------------

def check_axes(ax, where: str, many: bool = False) -> list:
    """The matplotlib Axes ``ax`` (with ``many``: a sequence or array of them) as a list, or a TypeError naming
    ``where``'s ``ax`` and what it takes (a Figure is told to pass one of its Axes)."""
    import numpy as np
    from matplotlib.axes import Axes

    items = list(np.asarray(ax, dtype=object).ravel()) if many and isinstance(ax, (list, tuple, np.ndarray)) else [ax]
    for a in items:
        if not isinstance(a, Axes):
            hint = "; pass one of its Axes (fig.axes[0], or fig.add_subplot())" if hasattr(a, "add_subplot") else ""
            raise TypeError(f"{where}: ax: expected a matplotlib Axes{' or a list of them' if many else ''} (or None "
                            f"for a new figure), got {type(a).__name__} {a!r:.40}{hint}")
    return items


def figure_axes(ax=None, rows: int = 1, cols: int = 1, size: tuple[float, float] | None = None,
                where: str = "plot", **kw):
    """(figure, axes) to draw on: ``ax`` and its figure when given (one Axes, else a TypeError naming
    ``where``), else a new figure of ``rows`` x ``cols`` axes (a single Axes, or an array squeezed as matplotlib
    does). The caller's pyplot backend is kept, so a notebook shows the figure inline."""
    if ax is not None:
        check_axes(ax, where)
        return ax.figure, ax
    import matplotlib.pyplot as plt

    size = size or (6.4 * cols, 2.6 + 1.9 * rows)
    return plt.subplots(rows, cols, figsize=size, squeeze=rows * cols == 1, **kw)


def display_unit(name: str, file_unit: str | None = None, si_unit: str = "") -> tuple[str, float]:
    """(unit shown, factor: shown = SI * factor) for a series: the unit the dataset's file gives it where
    known (so a spin written in rpm is shown in rpm), else the observable's display unit (``unit``)."""
    if file_unit is not None and (file_unit or si_unit):
        from .units import unit_factor

        try:
            return file_unit or "-", 1.0 / unit_factor(file_unit, si_unit, name)
        except Exception:  # a unit the file gave but that does not convert: fall back, never fail a plot
            pass
    shown, factor = unit(name)
    return ("-" if shown in ("", "-") else shown), factor


def axis_label(name: str, shown: str) -> str:
    """'spin omega [rpm]' for a series name and the unit it is shown in."""
    return f"{NAMES.get(name, name)} [{shown}]"
