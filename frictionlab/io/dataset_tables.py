"""The tables of a dataset file beside its columns, each checked against the columns and one another: [scene]
(a Scene, or an OutcomeScene for one impact per row; the observable it can produce, the time column's unit
against its duration), [fixed] law parameters, [reported] and the top-level keys. Each error is a one-line
DatasetError naming the file and the field (``dataset.load_dataset`` reads the file).
"""
from __future__ import annotations

import math

import numpy as np

from ..core.errors import DatasetError, FrictionLabError
from ..core.units import check_one_number, check_text, check_time_scale
from ..physics.scene import Scene
from ..solve.outcome import OutcomeScene
from .csvread import _line_of_row


def _table(meta, key, path, where=None):
    """An optional TOML table: {} when absent, an error when present but not a table."""
    value = meta.get(key, {})
    if not isinstance(value, dict):
        raise DatasetError(f"{path}: {where or key} must be a table, got {type(value).__name__} {value!r}")
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
                    text = check_text(value, f"{path}: {table}.{key}")
                    if table == "reported" and text[:1].isdigit():  # a quantity: one number and its unit
                        check_one_number(text, f"{path}: {table}.{key}", value)
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


def _quantity(value, si, where):
    from ..core.units import to_si

    try:
        return to_si(value, si, where)
    except FrictionLabError as exc:
        raise DatasetError(str(exc)) from None
