"""Datasets: a CSV series plus a TOML sidecar of the same stem, loaded into SI arrays.

The TOML holds ``name``, ``kind``, ``observable``, ``[columns]`` (column -> unit),
``[noise]`` (observable -> quantity), ``[scene]``, ``[fixed]`` law parameters,
``[provenance]`` and optionally ``[reported]``. Loading validates everything and fails
with a one-line ``DatasetError`` naming the file and the field.
"""
from __future__ import annotations

import math
import tomllib
from importlib import resources
from pathlib import Path

import attrs
import numpy as np

from .errors import DatasetError, FrictionLabError
from .scene import KINDS, Scene
from .units import unit_factor

PROVENANCE_KINDS = ("measured", "reported", "reconstructed", "synthetic")
DATA_KINDS = KINDS + ("contact-area",)

#: SI unit of each well-known column; other columns must declare a unit of their own.
COLUMN_SI = {
    "t": "s", "omega": "rad/s", "theta": "rad", "u": "m/s", "v": "m/s", "A": "m^2", "N": "N", "x": "m",
    "speed": "m/s", "incidence": "rad", "spin": "rad/s", "rebound_spin": "rad/s", "tangential_cor": "",
    "rebound_angle": "rad",
}


@attrs.frozen
class Provenance:
    kind: str  # measured | reported | reconstructed | synthetic
    source: str
    method: str = ""
    command: str = ""
    seed: int | None = None
    truth: dict = attrs.field(factory=dict)  # generating law and parameters, for synthetic data


@attrs.frozen(eq=False)
class Dataset:
    """A loaded dataset: SI arrays by column, the scene, fixed law parameters, provenance."""

    name: str
    kind: str
    observable: str
    path: Path | None
    columns: dict  # name -> SI ndarray
    units: dict  # name -> unit string as written in the TOML
    noise: dict  # column -> SI float (standard deviation)
    scene: Scene | None
    fixed: dict  # law parameter name -> SI float
    provenance: Provenance
    description: str = ""
    reported: dict = attrs.field(factory=dict)
    fixed_units: dict = attrs.field(factory=dict)

    @property
    def t(self) -> np.ndarray:
        return self.columns["t"]

    @property
    def y(self) -> np.ndarray:
        return self.columns[self.observable]

    @property
    def sigma(self) -> float:
        return self.noise[self.observable]

    def __len__(self) -> int:
        return len(next(iter(self.columns.values())))

    def __repr__(self) -> str:
        return f"<Dataset {self.name}: {self.kind}, {len(self)} points of {self.observable}, {self.provenance.kind}>"


def builtin_dir() -> Path:
    """Folder of the built-in datasets (the repository's datasets/, installed as frictionlab.data)."""
    return Path(str(resources.files("frictionlab.data")))


def builtin_names() -> list[str]:
    return sorted(p.stem for p in builtin_dir().glob("*.toml"))


def resolve(name_or_path: str | Path) -> Path:
    """Path of a dataset TOML from a built-in name, a .toml path or a .csv path."""
    p = Path(name_or_path)
    if p.suffix in (".toml", ".csv"):
        p = p.with_suffix(".toml")
        if not p.exists():
            raise DatasetError(f"{p}: no such dataset file")
        return p
    candidate = builtin_dir() / f"{name_or_path}.toml"
    if candidate.exists():
        return candidate
    raise DatasetError(f"unknown dataset '{name_or_path}'; built-in: {', '.join(builtin_names())} (or give a .toml path)")


def load_dataset(name_or_path: str | Path) -> Dataset:
    """Load and validate a dataset by built-in name or path to its TOML (or CSV)."""
    if isinstance(name_or_path, Dataset):
        return name_or_path
    path = resolve(name_or_path)
    try:
        meta = tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise DatasetError(f"{path}: TOML does not parse: {exc}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise DatasetError(f"{path}: cannot read: {exc}") from None
    return from_meta(meta, path)


def _req(meta, key, path, typ=str):
    if key not in meta:
        raise DatasetError(f"{path}: missing required key '{key}'")
    if not isinstance(meta[key], typ):
        raise DatasetError(f"{path}: '{key}' must be a {typ.__name__ if isinstance(typ, type) else 'table'}")
    return meta[key]


def from_meta(meta: dict, path: Path) -> Dataset:
    """Build a Dataset from a parsed TOML dict whose CSV sits beside ``path``."""
    name = _req(meta, "name", path)
    kind = _req(meta, "kind", path)
    if kind not in DATA_KINDS:
        raise DatasetError(f"{path}: kind = {kind!r}, expected one of {', '.join(DATA_KINDS)}")
    observable = _req(meta, "observable", path)
    units = _req(meta, "columns", path, dict)
    for col, u in units.items():
        if not isinstance(u, str):
            raise DatasetError(f"{path}: columns.{col} must be a unit string like 'us' or 'rpm'")
    if "t" not in units and kind != "impact-outcome":
        raise DatasetError(f"{path}: [columns] must declare the time column 't'")
    if observable not in units:
        raise DatasetError(f"{path}: observable {observable!r} is not declared in [columns] ({', '.join(units)})")

    csv = path.with_suffix(".csv")
    raw = read_csv(csv)
    columns = {}
    for col, unit in units.items():
        if col not in raw:
            raise DatasetError(f"{csv}: missing column '{col}' declared in {path.name} (has: {', '.join(raw)})")
        si = COLUMN_SI.get(col)
        if si is None:
            raise DatasetError(f"{path}: column '{col}' is not a known quantity ({', '.join(COLUMN_SI)})")
        try:
            columns[col] = raw[col] * unit_factor(unit, si, f"{path}: columns.{col}")
        except FrictionLabError as exc:
            raise DatasetError(str(exc)) from None
    if "t" in columns:
        t = columns["t"]
        bad = np.nonzero(np.diff(t) <= 0)[0]
        if bad.size:
            i = int(bad[0])
            raise DatasetError(f"{csv}: column 't' must increase strictly; line {_line_of_row(csv, i + 1)} "
                               f"({raw['t'][i + 1]!r}) does not exceed the line before ({raw['t'][i]!r})")
    for col in ("A", "N"):
        if col in columns and np.any(columns[col] < 0):
            raise DatasetError(f"{csv}: column '{col}' has negative values")

    noise_spec = meta.get("noise", {})
    if not isinstance(noise_spec, dict) or observable not in noise_spec:
        raise DatasetError(f"{path}: [noise] must give the noise of the observable, e.g. {observable} = '100 rpm'")
    noise = {}
    for col, value in noise_spec.items():
        if col not in columns:
            raise DatasetError(f"{path}: noise.{col} names no declared column")
        noise[col] = _quantity(value, COLUMN_SI[col], f"{path}: noise.{col}")
        if not noise[col] > 0:
            raise DatasetError(f"{path}: noise.{col} must be positive, got {value!r}")

    provenance = _provenance(meta.get("provenance"), path)
    scene = None
    if kind != "contact-area":
        spec = meta.get("scene")
        if not isinstance(spec, dict):
            raise DatasetError(f"{path}: missing required table [scene]")
        try:
            scene = Scene.from_spec(spec, kind, str(path), columns, columns.get("t"))
        except FrictionLabError as exc:
            raise DatasetError(str(exc)) from None

    fixed, fixed_units = {}, {}
    for key, value in meta.get("fixed", {}).items():
        from .registry import available_laws

        units_of = {s.name: s.unit for law in available_laws().values() for s in law.params}
        if key not in units_of:
            raise DatasetError(f"{path}: fixed.{key} is not a parameter of any registered law")
        fixed[key] = _quantity(value, units_of[key], f"{path}: fixed.{key}")
        fixed_units[key] = units_of[key]

    extra = set(meta) - {"name", "kind", "observable", "columns", "noise", "scene", "fixed", "provenance",
                         "reported", "description"}
    if extra:
        raise DatasetError(f"{path}: unknown top-level key(s) {sorted(extra)}")
    return Dataset(name=name, kind=kind, observable=observable, path=path, columns=columns, units=dict(units),
                   noise=noise, scene=scene, fixed=fixed, provenance=provenance,
                   description=meta.get("description", ""), reported=meta.get("reported", {}),
                   fixed_units=fixed_units)


def _quantity(value, si, where):
    from .units import to_si

    try:
        return to_si(value, si, where)
    except FrictionLabError as exc:
        raise DatasetError(str(exc)) from None


def _provenance(p, path) -> Provenance:
    if not isinstance(p, dict):
        raise DatasetError(f"{path}: missing required table [provenance] (kind = {' | '.join(PROVENANCE_KINDS)})")
    kind = p.get("kind")
    if kind not in PROVENANCE_KINDS:
        raise DatasetError(f"{path}: provenance.kind = {kind!r}, expected one of {', '.join(PROVENANCE_KINDS)}")
    if not isinstance(p.get("source"), str) or not p["source"]:
        raise DatasetError(f"{path}: provenance.source must name where the data come from")
    if kind in ("reconstructed", "synthetic") and not p.get("command"):
        raise DatasetError(f"{path}: provenance.command must give the command that regenerates {kind} data")
    return Provenance(kind=kind, source=p["source"], method=p.get("method", ""), command=p.get("command", ""),
                      seed=p.get("seed"), truth=p.get("truth", {}))


def read_csv(csv: Path) -> dict[str, np.ndarray]:
    """Read a numeric CSV with a header row into float arrays; one-line errors on bad content."""
    import pandas as pd

    try:
        df = pd.read_csv(csv, comment="#", skipinitialspace=True)
    except FileNotFoundError:
        raise DatasetError(f"{csv}: no such file") from None
    except pd.errors.EmptyDataError:
        raise DatasetError(f"{csv}: file is empty") from None
    except (pd.errors.ParserError, UnicodeDecodeError, ValueError) as exc:
        raise DatasetError(f"{csv}: CSV does not parse: {str(exc).splitlines()[0]}") from None
    if len(df) == 0:
        raise DatasetError(f"{csv}: no data rows")
    out = {}
    for col in df.columns:
        values = pd.to_numeric(df[col], errors="coerce").to_numpy(dtype=float)
        bad = np.nonzero(~np.isfinite(values))[0]
        if bad.size:
            i = int(bad[0])
            raise DatasetError(f"{csv}: column '{col}' line {_line_of_row(csv, i)}: {df[col].iloc[i]!r} "
                               "is not a finite number")
        out[str(col).strip()] = values
    return out


def _line_of_row(csv: Path, row: int) -> int:
    """1-based line number in the file of data row ``row`` (0-based, after header and comments)."""
    lines = Path(csv).read_text(encoding="utf-8", errors="replace").splitlines()
    data = [i for i, line in enumerate(lines) if line.strip() and not line.lstrip().startswith("#")]
    return data[row + 1] + 1 if row + 1 < len(data) else len(lines)
