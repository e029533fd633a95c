"""Scenes column-wise (``SceneBatch``) and law parameters per scene (``batch_params``) for the batch engine."""
from __future__ import annotations

from collections.abc import Mapping, Sequence

import attrs
import numpy as np

from ..core.errors import ParameterError, SceneError
from ..core.units import as_si, is_quantity, unit_factor
from ..physics.scene import Scene

_TOP = ("mass", "u0", "duration", "radius", "inertia_factor", "omega0", "incline")


def _is_number(x) -> bool:
    return isinstance(x, (int, float, np.floating, np.integer)) and not isinstance(x, bool)


def _structure(scene: Scene):
    return (scene.kind, scene.effects, type(scene.area), type(scene.normal), scene.compliance is None,
            scene.radius is None, scene.incline is None)


def _model_fields(model):
    return [] if model is None else [f.name for f in attrs.fields(type(model)) if f.init]


@attrs.frozen(eq=False)
class SceneBatch:
    """n scenes of one structure: a template Scene plus per-scene values of its numeric fields.

    ``values`` maps a field path ('mass', 'u0', 'area.peak', 'normal.impulse', ...) to an (n,)
    array in SI; fields not listed take the template's value for every scene.
    """

    template: Scene
    values: dict
    n: int

    @classmethod
    def from_scenes(cls, scenes: Sequence[Scene]) -> "SceneBatch":
        scenes = list(scenes)
        if not scenes:
            raise SceneError("batch: no scenes given")
        first = scenes[0]
        key = _structure(first)
        for i, s in enumerate(scenes):
            if not isinstance(s, Scene):
                raise SceneError(f"batch: item {i} is a {type(s).__name__}, not a Scene")
            if _structure(s) != key:
                raise SceneError(f"batch: scene {i} differs in structure (kind, effects or area/normal model) from "
                                 "scene 0; simulate scenes of one structure per batch")
        values = {}
        paths = [(name, None) for name in _TOP]
        paths += [("area", f) for f in _model_fields(first.area)] + [("normal", f) for f in _model_fields(first.normal)]
        for top, field in paths:
            if field is None:
                col = [getattr(s, top) for s in scenes]
                path = top
            else:
                col = [getattr(getattr(s, top), field) for s in scenes]
                path = f"{top}.{field}"
            ref = col[0]
            if _is_number(ref):
                arr = np.array(col, dtype=float)
                if np.any(arr != arr[0]):
                    values[path] = arr
            elif any(c is not ref for c in col[1:]):
                raise SceneError(f"batch: scenes differ in {path}, which cannot be vectorized; "
                                 "share one model object or simulate them one by one")
        return cls(first, values, len(scenes))

    @classmethod
    def sweep(cls, template: Scene, values: Mapping[str, np.ndarray]) -> "SceneBatch":
        """A batch from a template and arrays for some of its numeric fields (all of one length)."""
        arrays = {k: np.asarray(v, dtype=float).ravel() for k, v in values.items()}
        sizes = {a.size for a in arrays.values()}
        if len(sizes) != 1:
            raise SceneError(f"batch: sweep arrays differ in length ({sorted(sizes)})")
        known = set(_TOP) | {f"area.{f}" for f in _model_fields(template.area)} | {
            f"normal.{f}" for f in _model_fields(template.normal)}
        bad = sorted(set(arrays) - known)
        if bad:
            raise SceneError(f"batch: unknown scene field(s) {bad}; known: {', '.join(sorted(known))}")
        return cls(template, arrays, sizes.pop())

    def view(self, idx=None, column: bool = False) -> Scene:
        """A Scene whose varying fields are arrays over scenes ``idx`` (shape (k,), or (k, 1) with column)."""
        def take(a):
            a = a if idx is None else a[idx]
            return a[:, None] if column else a

        return self._with({path: take(a) for path, a in self.values.items()})

    def scene(self, i: int) -> Scene:
        """Scene i as an ordinary Scene of floats."""
        return self._with({path: float(a[i]) for path, a in self.values.items()})

    def _with(self, values) -> Scene:
        top, area, normal = {}, {}, {}
        for path, a in values.items():
            head, _, field = path.partition(".")
            {"area": area, "normal": normal}.get(head, top)[field or head] = a
        s = self.template
        if area:
            top["area"] = attrs.evolve(s.area, **area)
        if normal:
            top["normal"] = attrs.evolve(s.normal, **normal)
        return attrs.evolve(s, **top) if top else s

    def subset(self, idx) -> "SceneBatch":
        """The scenes ``idx`` (an index array or slice) as a batch of their own."""
        idx = np.arange(self.n)[idx]
        return SceneBatch(self.template, {k: v[idx] for k, v in self.values.items()}, int(idx.size))

    def tile(self, k: int) -> "SceneBatch":
        """The batch k times over: scene i of copy j is scene j n + i."""
        return SceneBatch(self.template, {f: np.tile(v, k) for f, v in self.values.items()}, self.n * k)

    def __len__(self) -> int:
        return self.n


def batch_params(law, params, n: int) -> dict:
    """Law parameters for n scenes: name -> float (shared) or (n,) array, checked against bounds.

    ``params`` is None (defaults), a mapping of name -> scalar or (n,) array, or a sequence of n mappings; a
    value is SI, or a quantity string, or a pint Quantity (scalar or array).
    """
    if params is None:
        params = {}
    if not isinstance(params, Mapping):
        rows = list(params)
        if len(rows) != n:
            raise ParameterError(f"batch: {len(rows)} parameter sets for {n} scenes")
        names = set().union(*[set(r) for r in rows]) if rows else set()
        params = {k: np.array([r.get(k, law.spec(k).default) for r in rows], dtype=float) for k in names}
    out = {}
    for spec in law.params:
        v = params.get(spec.name, spec.default)
        if isinstance(v, str) or is_quantity(v):  # a quantity string, or a pint Quantity (one value or an array)
            where = f"law '{law.name}': {spec.name}"
            v = as_si(v, spec.unit, where) if isinstance(v, str) or np.ndim(v.magnitude) == 0 else \
                np.asarray(v.magnitude, dtype=float) * unit_factor(str(v.units), spec.unit, where)
        a = np.asarray(v, dtype=float)
        if a.ndim == 0:
            a = float(a)
        elif a.shape != (n,):
            raise ParameterError(f"batch: parameter {spec.name} has shape {a.shape}, expected ({n},) or a scalar")
        bad = ~(np.isfinite(a) & (a >= spec.lower) & (a <= spec.upper))
        if np.any(bad):
            i = int(np.argmax(np.atleast_1d(bad)))
            val = np.atleast_1d(a)[i]
            raise ParameterError(f"law '{law.name}': {spec.name} = {val!r} {spec.unit} (scene {i}) is outside its bounds "
                                 f"[{spec.lower:g}, {spec.upper:g}]")
        out[spec.name] = a
    for k in params:
        law.spec(k)  # unknown names raise ParameterError
    return out


def take_params(p, idx, column=False):
    def take(v):
        if isinstance(v, float):
            return v
        v = v[idx]
        return v[:, None] if column else v

    return {k: take(v) for k, v in p.items()}
