"""The fields of a dataset's TOML and the columns of its CSV, each read and checked: every error one line
naming the file and the field. ``dataset.from_meta`` builds the Dataset from them."""
from __future__ import annotations

import math

import numpy as np

from ..core.errors import DatasetError, FrictionLabError
from ..core.names import check_name
from ..core.units import MAX_SI, check_text, check_time_scale, unit_factor
from ..physics.scene import KINDS, Scene
from ..solve.outcome import OUTCOMES, OutcomeScene
from .csvread import _line_of_row

DATA_KINDS = KINDS + ("contact-area",)

#: SI unit of each well-known column; other columns must declare a unit of their own.
COLUMN_SI = {
    "t": "s", "omega": "rad/s", "theta": "rad", "u": "m/s", "v": "m/s", "A": "m^2", "N": "N", "x": "m",
    "speed": "m/s", "incidence": "rad", "spin": "rad/s", "rebound_spin": "rad/s", "tangential_cor": "",
    "rebound_angle": "rad", "cm_tangential_cor": "", "normal_cor": "", "contact_rebound_angle": "rad", "psi1": "",
    "psi2": "", "mu": "",
}


def _req(meta, key, path, typ=str):
    if key not in meta:
        raise DatasetError(f"{path}: missing required key '{key}'")
    if not isinstance(meta[key], typ):
        what = {str: "string", dict: "table"}.get(typ, typ.__name__)
        raise DatasetError(f"{path}: '{key}' must be a {what}, got {type(meta[key]).__name__}")
    return meta[key]


def _table(meta, key, path, where=None):
    """An optional TOML table: {} when absent, an error when present but not a table."""
    value = meta.get(key, {})
    if not isinstance(value, dict):
        raise DatasetError(f"{path}: {where or key} must be a table, got {type(value).__name__} {value!r}")
    return value


def _header(meta, path):
    """name, group, kind, observable and the [columns] units, checked against one another."""
    name = check_name(_req(meta, "name", path), f"{path}: name", DatasetError)
    group = meta.get("group", "")
    if "group" in meta:
        if not isinstance(group, str):
            raise DatasetError(f"{path}: group = {group!r}, expected a quoted name (letters, digits, . _ + -)")
        group = check_name(group, f"{path}: group", DatasetError)
    kind = _req(meta, "kind", path)
    if kind not in DATA_KINDS:
        raise DatasetError(f"{path}: kind = {kind!r}, expected one of {', '.join(DATA_KINDS)}")
    observable = _req(meta, "observable", path)
    if observable == "t":
        raise DatasetError(f"{path}: observable = 't': the time column cannot be the observable")
    if kind == "impact-outcome":
        if observable not in OUTCOMES:
            raise DatasetError(f"{path}: observable {observable!r} is not an impact outcome ({', '.join(OUTCOMES)})")
    units = _req(meta, "columns", path, dict)
    for col, u in units.items():
        if not isinstance(u, str):
            raise DatasetError(f"{path}: columns.{col} must be a unit string like 'us' or 'rpm'")
    if "t" not in units and kind != "impact-outcome":
        raise DatasetError(f"{path}: [columns] must declare the time column 't'")
    if observable not in units:
        raise DatasetError(f"{path}: observable {observable!r} is not declared in [columns] ({', '.join(units)})")
    return name, group, kind, observable, units


def _columns(raw, units, path, csv) -> dict:
    """The declared columns of the CSV in SI units, each a known quantity of sane magnitude."""
    columns = {}
    for col, unit in units.items():
        if col not in raw:
            raise DatasetError(f"{csv}: missing column '{col}' declared in {path.name} (has: {_names(raw)})")
        si = COLUMN_SI.get(col)
        if si is None:
            raise DatasetError(f"{path}: column '{col}' is not a known quantity ({', '.join(COLUMN_SI)})")
        try:
            columns[col] = raw[col] * unit_factor(unit, si, f"{path}: columns.{col}")
        except FrictionLabError as exc:
            raise DatasetError(str(exc)) from None
        bad = np.nonzero(~(np.abs(columns[col]) <= MAX_SI))[0]
        if bad.size:
            i = int(bad[0])
            raise DatasetError(f"{csv}: column {col!r} line {_line_of_row(csv, i)}: {raw[col][i]:g} {unit} is beyond "
                               f"the accepted magnitude {MAX_SI:g} in SI units")
    return columns


def _time_origin(meta, columns, raw, kind, path, csv) -> float:
    """The file's time of t = 0 [s] (TOML ``time_zero``, default 0), subtracted from column t in place.

    Times count from first contact, release or the start of the load-point schedule; a column that
    starts elsewhere (a later first frame, a lab clock, epoch seconds) is an error unless ``time_zero``
    says where t = 0 lies: an offset is never guessed, so no series is fitted against the wrong origin."""
    if "time_zero" not in meta:
        if "t" in columns and kind != "contact-area" and columns["t"][0] > 0:  # negative: _check_series
            first = raw["t"][0]
            raise DatasetError(f"{csv}: column 't' starts at {first:.10g}, not 0: times count from first contact (or "
                               f"release, or the start of loading); say where t = 0 lies in the file's clock with "
                               f"time_zero = \"{first:.10g} <unit>\" at the top of {path.name} (subtracted from t), "
                               "or time_zero = \"0 s\" if the first sample is later than t = 0")
        return 0.0
    if "t" not in columns:
        raise DatasetError(f"{path}: time_zero needs a time column 't'")
    zero = _quantity(meta["time_zero"], "s", f"{path}: time_zero")
    if columns["t"][0] < zero:
        raise DatasetError(f"{path}: time_zero = {meta['time_zero']!r} is after the first time in {csv.name} "
                           f"({raw['t'][0]:.10g}): t = 0 must not lie after the first sample")
    columns["t"] = columns["t"] - zero
    return zero


def _check_series(columns, raw, kind, csv) -> None:
    """Time increases strictly and starts at t >= 0; areas and normal forces are not negative."""
    if "t" in columns:
        t = columns["t"]
        bad = np.nonzero(np.diff(t) <= 0)[0]
        if bad.size:
            i = int(bad[0])
            raise DatasetError(f"{csv}: column 't' must increase strictly; line {_line_of_row(csv, i + 1)} "
                               f"({raw['t'][i + 1]:g}) does not exceed the line before ({raw['t'][i]:g})")
        if kind != "contact-area" and t[0] < 0:
            raise DatasetError(f"{csv}: column 't' line {_line_of_row(csv, 0)}: time {raw['t'][0]:g} is negative; "
                               "times count from first contact (or release) at t = 0")
    for col in ("A", "N"):
        if col in columns and np.any(columns[col] < 0):
            raise DatasetError(f"{csv}: column '{col}' has negative values")

def _si_of(col, value, where):
    """A declared noise value of column ``col`` in SI."""
    return _quantity(value, COLUMN_SI[col], where)


#: ``[noise] correlation``: the samples' noise independent ('none', the default) or first-order autoregressive
#: ('ar1': its coefficient profiled by each fit, inference/noise/ar1.py) or chosen by the data ('arp': AR(p) by BIC
#: per sampling rate, ARMA(1,1) where the order runs to its cap, fitted with the law; inference/noise/).
NOISE_CORRELATIONS = ("none", "ar1", "arp")


def _correlation(value, path) -> str:
    if not isinstance(value, str) or value not in NOISE_CORRELATIONS:
        raise DatasetError(f"{path}: noise.correlation = {value!r}, expected one of {', '.join(NOISE_CORRELATIONS)} "
                           "(none: independent samples; ar1: first-order autoregressive noise, phi fitted; arp: an "
                           "AR(p) model chosen by the data)")
    return value


def _scene(meta, path, kind, observable, columns, units, csv):
    """The [scene] table as a Scene (or OutcomeScene); None for a contact-area series."""
    if kind == "contact-area":
        return None
    spec = meta.get("scene")
    if not isinstance(spec, dict):
        raise DatasetError(f"{path}: missing required table [scene]")
    try:
        if kind == "impact-outcome":
            scene = OutcomeScene.from_spec(spec, str(path))
        else:
            scene = Scene.from_spec(spec, kind, str(path), columns, columns.get("t"))
    except FrictionLabError as exc:  # a model's own check (no file in it) still names the file
        raise DatasetError(str(exc) if str(exc).startswith(str(path)) else f"{path}: [scene]: {exc}") from None
    if kind == "impact-outcome":
        _check_outcome_rows(columns, observable, path, csv, scene)
    else:
        _check_observable(scene, observable, path)
        _check_time_unit(columns, units, spec, kind, scene, path)
    return scene


def _fixed(table, path):
    """[fixed] law parameters in SI, each a parameter of some registered law and within its bounds."""
    from ..physics.registry import available_laws

    fixed, fixed_units = {}, {}
    for key, value in table.items():
        specs = [(law.name, s) for law in available_laws().values() for s in law.params if s.name == key]
        if not specs:
            raise DatasetError(f"{path}: fixed.{key} is not a parameter of any registered law")
        unit = specs[0][1].unit
        fixed[key] = _quantity(value, unit, f"{path}: fixed.{key}")
        fixed_units[key] = unit
        for law_name, spec in specs:
            if spec.unit == unit and not spec.lower <= fixed[key] <= spec.upper:
                raise DatasetError(f"{path}: fixed.{key} = {value!r} is outside the bounds of law '{law_name}' "
                                   f"[{spec.lower:g}, {spec.upper:g}] {spec.unit}".rstrip())
    return fixed, fixed_units


def _rest(meta, path, provenance) -> dict:
    """No unknown top-level key; [reported] and provenance.truth readable later; returns [reported]."""
    extra = set(meta) - {"name", "group", "kind", "observable", "columns", "noise", "scene", "fixed", "provenance",
                         "reported", "description", "time_zero", "stated"}
    if extra:
        raise DatasetError(f"{path}: unknown top-level key(s) {sorted(extra)}")
    reported = _table(meta, "reported", path, "[reported]")
    for table, values in (("reported", reported), ("provenance.truth", provenance.truth)):
        for key, value in values.items():  # read by the report later: refuse what pint would choke on now
            if isinstance(value, str):
                try:
                    check_text(value, f"{path}: {table}.{key}")
                except FrictionLabError as exc:
                    raise DatasetError(str(exc)) from None
    if not isinstance(meta.get("description", ""), str):
        raise DatasetError(f"{path}: 'description' must be a string")
    return reported


def _check_time_unit(columns, units, spec, kind, scene, path) -> None:
    """The time column must span about the scene's duration (given, or the impact's contact time)."""
    if "duration" in spec:
        field = "scene.duration"
    elif kind == "impact" and scene.duration > 0:
        field = "the scene's contact time"
    else:
        return  # the duration was taken from the time column itself
    try:
        check_time_scale(float(columns["t"][-1]), scene.duration, units["t"], f"{path}: columns.t", field)
    except FrictionLabError as exc:
        raise DatasetError(str(exc)) from None


#: Trajectory series each observable needs, and what in a scene provides it.
def _check_observable(scene: Scene, observable: str, path) -> None:
    """A dataset whose observable its own scene cannot produce would be fitted against zeros."""
    if scene.kind not in ("impact", "incline"):
        return
    if observable in ("omega", "theta") and not ({"spin", "slip-coupling"} & scene.effects):
        raise DatasetError(f"{path}: observable {observable!r} needs the scene to integrate spin; "
                           "add \"spin\" to scene.effects (and a scene.radius)")
    if observable == "A" and scene.area is None:
        raise DatasetError(f"{path}: observable 'A' needs a [scene.area] model")
    if observable == "N" and scene.normal is None:
        raise DatasetError(f"{path}: observable 'N' needs a [scene.normal] model")


def _check_outcome_rows(columns, observable, path, csv, scene) -> None:
    """An impact-outcome dataset: one impact per row (speed, incidence), an outcome as observable."""
    for col in ("speed", "incidence"):
        if col not in columns:
            raise DatasetError(f"{path}: an impact-outcome dataset needs a '{col}' column in [columns] "
                               "(one impact per row)")
    bad = np.nonzero(~(columns["speed"] > 0))[0]
    if bad.size:
        raise DatasetError(f"{csv}: column 'speed' line {_line_of_row(csv, int(bad[0]))}: impact speed must be positive")
    inc = columns["incidence"]
    bad = np.nonzero(~((inc > 0) & (inc < math.pi / 2)))[0]
    if bad.size:
        raise DatasetError(f"{csv}: column 'incidence' line {_line_of_row(csv, int(bad[0]))}: incidence must be "
                           f"strictly between 0 and 90 deg (measured from the "
                           f"{'surface normal' if scene.angle_reference == 'normal' else 'surface'})")


def _names(columns) -> str:
    """Column names for a one-line message (repr when a name holds odd characters)."""
    return ", ".join(c if c.isprintable() and "," not in c else repr(c) for c in columns)


def _si_of(col, value, where):
    """A declared noise value of column ``col`` in SI."""
    return _quantity(value, COLUMN_SI[col], where)


def _quantity(value, si, where):
    from ..core.units import to_si

    try:
        return to_si(value, si, where)
    except FrictionLabError as exc:
        raise DatasetError(str(exc)) from None
