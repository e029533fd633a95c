"""Reading a ``[scene]`` table and checking Python-built scene models: shared by the scene's parts.

Validators for attrs fields (no NaN or negative size slips through), the quantity reader with
one-line errors naming the file and field, the ``effects`` list, and small key checks.
"""
from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from ..core.errors import SceneError
from ..core.units import to_si

#: Effects a scene may switch on in its ``effects`` list.
EFFECTS = {
    "spin": "integrate spin omega and rotation angle theta from the friction torque (needs radius)",
    "slip-coupling": "contact-point slip u = v - r omega (rigid sphere) instead of u = v",
    "compliance": ("tangential compliance at the contact (Maw, Barber and Fawcett 1976): [scene.compliance] "
                   "model = 'linear' (spring and damper), 'mindlin' (k_t = 8 G* a(t) from [scene.materials]) or "
                   "'mindlin-deresiewicz' (microslip and loading history, impact outcomes; frictionlab.physics.mdr)"),
    "gravity": "gravity along an incline, m g sin(alpha), with N = m g cos(alpha)",
}



# --- validation of Python-built models: no NaN or negative size slips through ----------
def _number(test, words):
    def check(instance, attribute, value):
        if isinstance(value, float) and math.isfinite(value) and test(value):  # the common case (float, np.float64)
            return
        # a batch view (frictionlab.solve.batch) puts arrays over scenes in these fields: check every element
        v = None if isinstance(value, (bool, np.bool_)) else np.asarray(value)
        ok = v is not None and v.dtype.kind in "fi"
        if not ok or not np.isfinite(v).all() or not np.asarray(test(v)).all():
            raise SceneError(f"{type(instance).__name__}.{attribute.name} must be {words}, got {value!r}")
    return check


positive = _number(lambda v: v > 0, "a positive finite number")
nonnegative = _number(lambda v: v >= 0, "a finite number >= 0")
finite = _number(lambda v: True, "a finite number")


def optional(check):
    def optional(instance, attribute, value):
        if value is not None:
            check(instance, attribute, value)
    return optional


# --- reading a [scene] table --------------------------------------------------------------
def spec_reader(spec: Mapping, where: str):
    """q(key, unit, table=spec, prefix='scene', required=True, positive=True, default=None) -> SI float.

    Reads a quantity string from a TOML table with one-line errors naming file and field.
    """
    def q(key, unit, table=spec, prefix="scene", required=True, positive=True, default=None):
        if key not in table:
            if required:
                raise SceneError(f"{where}: [{prefix}] is missing '{key}'")
            return default
        value = to_si(table[key], unit, f"{where}: {prefix}.{key}")
        if positive and not value > 0:
            raise SceneError(f"{where}: {prefix}.{key} must be positive, got {table[key]!r}")
        return value

    return q


def read_effects(spec: Mapping, where: str, default=()) -> frozenset:
    """The ``effects`` list of a [scene] table, checked against EFFECTS."""
    effects = spec.get("effects", list(default))
    if not isinstance(effects, list) or not all(isinstance(e, str) for e in effects):
        raise SceneError(f"{where}: scene.effects must be a list of names")
    bad = [e for e in effects if e not in EFFECTS]
    if bad:
        raise SceneError(f"{where}: scene.effects: unknown effect(s) {bad}; known: {', '.join(EFFECTS)}")
    return frozenset(effects)


def column_of(columns, name, where, prefix, quantity):
    if "t" not in columns:
        raise SceneError(f"{where}: {prefix}.model = 'column' needs the time column 't'")
    if name != quantity:
        raise SceneError(f"{where}: {prefix}.column = {name!r}: the column must be the {quantity!r} column")
    if name not in columns:
        raise SceneError(f"{where}: {prefix}.column = {name!r} is not a column of the CSV (has: {', '.join(map(str, columns))})")
    return columns[name]



def known_keys(table, keys, where, label):
    extra = set(table) - set(keys)
    if extra:
        raise SceneError(f"{where}: {label} has unknown key(s) {sorted(extra)}; "
                         f"known: {', '.join(sorted(keys)) or 'none'}")


def model_of(table, keys: dict, where: str, prefix: str):
    """The ``model`` named in a sub-table, its keys checked against ``keys[model]`` when the model is known."""
    model = table.get("model")
    if isinstance(model, str) and model in keys:
        known_keys(table, keys[model] | {"model"}, where, f"[{prefix}] with model {model!r}")
    return model
