"""Datasets: a CSV series plus a TOML sidecar of the same stem, loaded into SI arrays.

The TOML holds ``name``, optionally ``group`` (datasets of one material and setup compared
together; without it a dataset is its own group: nothing is inferred from names), ``kind``, ``observable``, ``[columns]`` (column -> unit),
``[noise]`` (``kind = "known" | "estimated" | "none"`` and column -> quantity: see NOISE_KINDS;
no table means estimated), ``[scene]``, ``[fixed]`` law parameters,
``[provenance]`` and optionally ``[reported]``, ``[stated]`` (the numbers a noise-free
reconstruction was drawn through, each ``name = ["value", "precision"]``, names from STATED: what
its laws are compared on) and ``time_zero`` (the file's time of t = 0, subtracted
from column t; a time column that starts elsewhere without it is an error). Loading validates everything and fails
with a one-line ``DatasetError`` naming the file and the field.
"""
from __future__ import annotations

import math
import os
from importlib import resources
from pathlib import Path

import attrs
import numpy as np

from typing import TYPE_CHECKING

from ..core.blas import one_blas_thread
from ..core.errors import DatasetError, FrictionLabError
from ..core.files import read_toml
from ..core.names import check_name
from ..core.units import MAX_SI, unit_factor
from ..physics.scene import KINDS, Scene
from .csvread import _line_of_row, read_csv
from .provenance import PROVENANCE_KINDS, Provenance, _provenance  # noqa: F401  (re-exported)
from ..solve.outcome import OUTCOMES
from .dataset_tables import _fixed, _quantity, _rest, _scene, _table
from .noise import NOISE_KINDS, STATED, noise_table, stated_table  # noqa: F401 (NOISE_KINDS, STATED: read from here too)

DATA_KINDS = KINDS + ("contact-area",)

#: SI unit of each well-known column; other columns must declare a unit of their own.
if TYPE_CHECKING:  # annotations only
    import pandas as pd
    from matplotlib.axes import Axes

COLUMN_SI = {
    "t": "s", "omega": "rad/s", "theta": "rad", "u": "m/s", "v": "m/s", "A": "m^2", "N": "N", "x": "m",
    "speed": "m/s", "incidence": "rad", "spin": "rad/s", "rebound_spin": "rad/s", "tangential_cor": "",
    "rebound_angle": "rad", "cm_tangential_cor": "", "normal_cor": "", "contact_rebound_angle": "rad", "psi1": "",
    "psi2": "", "mu": "",
}


@attrs.frozen(eq=False)
class Dataset:
    """A loaded dataset: SI arrays by column, the scene, fixed law parameters and provenance (made by
    `load_dataset`).

    Attributes
    ----------
    name, kind, observable : str
        The dataset's name, its scene kind and the column the laws are fitted to.
    columns : dict of str to numpy.ndarray
        The data by column, SI (``t`` [s], ``theta`` [rad], ``omega`` [rad/s], ``v`` [m/s], ``mu`` [-], ...).
    units : dict of str to str
        Each column's unit as its file writes it (what figures and tables show).
    noise : dict of str to float
        The noise standard deviation of each column [SI], known or estimated.
    noise_kind : {"known", "estimated", "none"}
        Whether sigma was measured, estimated from the data alone, or there is none (a reconstruction).
    scene : Scene or None
        The experiment the laws are solved on.
    fixed : dict of str to float
        Law parameters the dataset fixes [SI].
    provenance : Provenance
        Measured, reported, reconstructed or synthetic, with its source and the command that regenerates it.
    stated : dict
        For a reconstruction, the stated numbers (value, precision) the laws are compared on, SI.
    """

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
    noise_kind: str = "estimated"  # NOISE_KINDS: sigma measured ('known'), from the data ('estimated'), or 'none'
    noise_df: dict = attrs.field(factory=dict)  # column -> effective degrees of freedom of an estimated sigma
    noise_est: dict = attrs.field(factory=dict, repr=False)  # column -> noise.NoiseEstimate (estimated kind)
    noise_note: str = ""  # which noise is used, and why (one sentence, for the report and `datasets show`)
    noise_correlation: str = "none"  # NOISE_CORRELATIONS: independent ('none'), AR(1) ('ar1'), chosen by the data ('arp')
    stated: dict = attrs.field(factory=dict)  # STATED name -> (value, precision) in SI ([stated])
    group: str = ""  # declared group (TOML 'group'); "": the dataset is its own group (nothing is inferred from names)
    time_zero: float = 0.0  # the file's time of t = 0 [s] (TOML 'time_zero'), already subtracted from columns['t']

    @property
    def t(self) -> np.ndarray:
        """The time column [s]; a DatasetError for one impact per row (no time)."""
        if "t" not in self.columns:
            raise DatasetError(f"dataset '{self.name}' ({self.kind}) has no time column: one impact per row")
        return self.columns["t"]

    @property
    def y(self) -> np.ndarray:
        """The fitted column (the observable), SI."""
        return self.columns[self.observable]

    @property
    def sigma(self) -> float:
        """The observable's sigma [SI]: measured or estimated; nan for a noise-free reconstruction."""
        return self.noise.get(self.observable, math.nan) if self.noise_kind == "none" else self.noise[self.observable]

    def __len__(self) -> int:
        return len(next(iter(self.columns.values())))

    def to_dataframe(self) -> pd.DataFrame:
        """The columns as a pandas DataFrame.

        Returns
        -------
        pandas.DataFrame
            One column per data column, SI; units by column in ``df.attrs['units']``, the file's own units in
            ``df.attrs['file_units']``, the noise in ``df.attrs['noise']``.

        Examples
        --------
        >>> import frictionlab as fl
        >>> df = fl.load_dataset("incline-oil-a100").to_dataframe()
        >>> df.attrs["units"]["v"]
        'm/s'
        """
        import pandas as pd

        df = pd.DataFrame(self.columns)
        df.attrs.update(units={k: COLUMN_SI.get(k, "SI") for k in df.columns}, file_units=dict(self.units),
                        noise=dict(self.noise), noise_kind=self.noise_kind, provenance=self.provenance.kind)
        return df

    def __repr__(self) -> str:
        return f"<Dataset {self.name}: {self.kind}, {len(self)} points of {self.observable}, {self.provenance.kind}>"

    def shown(self, column: str) -> tuple[str, float]:
        """The unit a column is shown in: the unit its file gives it.

        Parameters
        ----------
        column : str
            A column name.

        Returns
        -------
        tuple of (str, float)
            The unit and the factor from SI: shown value = SI value * factor.
        """
        from ..core.display import display_unit

        return display_unit(column, self.units.get(column), COLUMN_SI.get(column, ""))

    def x_axis(self) -> tuple[str, str, float]:
        """What the observable is drawn against: time, or for one impact per row the incidence angle (else
        the row number, with column '').

        Returns
        -------
        tuple of (str, str, float)
            The column, the unit it is shown in, and the factor from SI.
        """
        for col in ("t", "incidence", "speed"):
            if col in self.columns:
                return (col, *self.shown(col))
        return "", "", 1.0

    def plot(self, y: str | None = None, ax: Axes | None = None, **style: object) -> Axes:
        """Draw a column against time, or against the incidence angle for one impact per row, in the units of
        the dataset's file, with its noise as error bars where sigma is known or estimated.

        Parameters
        ----------
        y : str, optional
            The column to draw; default the observable.
        ax : matplotlib.axes.Axes, optional
            Where to draw; default a new figure's axes.
        **style
            Passed to matplotlib's ``errorbar``.

        Returns
        -------
        matplotlib.axes.Axes
            The axes drawn on.

        Raises
        ------
        DatasetError
            No such column.
        """
        from ..core.display import axis_label, figure_axes

        y = y or self.observable
        if y not in self.columns:
            raise DatasetError(f"dataset '{self.name}' has no column '{y}'; it has {', '.join(self.columns)}")
        _, ax = figure_axes(ax, where="Dataset.plot")
        xcol, xunit, xf = self.x_axis()
        x = self.columns[xcol] * xf if xcol else np.arange(len(self))
        shown, f = self.shown(y)
        sigma = self.noise.get(y)
        style = {"fmt": "o", "ms": 3, "color": "black", "ecolor": "0.7", "elinewidth": 0.8,
                 "label": f"{self.name} ({self.provenance.kind})"} | style
        ax.errorbar(x, self.columns[y] * f, yerr=None if sigma is None or not np.isfinite(sigma) else sigma * f,
                    **style)
        ax.set_xlabel(axis_label({"t": "time", "incidence": "incidence"}.get(xcol, xcol), xunit) if xcol else "row")
        ax.set_ylabel(axis_label(y, shown))
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        return ax

    def check(self, where: str = "dataset") -> Dataset:
        """This dataset if it is still what loading made of it, else a DatasetError naming ``where`` and the field
        (``intact.check_intact``: what fit, simulate and compare call before using it)."""
        from .intact import check_intact

        check_intact(self, where)
        return self

    def _repr_html_(self) -> str:
        """A notebook's view: what the dataset is, where it comes from, its noise and columns in its units."""
        import html

        e = html.escape
        rows = []
        for col, values in self.columns.items():
            shown, f = self.shown(col)
            sigma = self.noise.get(col)
            noise = "" if sigma is None or not np.isfinite(sigma) else f"{sigma * f:.3g}"
            rows.append(f"<tr><td>{e(col)}{' (fitted)' if col == self.observable else ''}</td><td>{e(shown)}</td>"
                        f"<td>{np.min(values) * f:.4g}</td><td>{np.max(values) * f:.4g}</td><td>{e(noise)}</td></tr>")
        p = self.provenance
        return (f"<p><b>Dataset {e(self.name)}</b>: {e(self.kind)}, {len(self)} rows, fitted column "
                f"{e(self.observable)}; <b>{e(p.kind)}</b> ({e(getattr(p, 'source', '') or '')}); noise "
                f"{e(self.noise_kind)}{': ' + e(self.noise_note) if self.noise_note else ''}</p>"
                "<table><tr><th>column</th><th>unit</th><th>min</th><th>max</th><th>sigma</th></tr>"
                + "".join(rows) + "</table>")


def builtin_dir() -> Path:
    """Folder of the built-in datasets (``frictionlab/data/``, the package ``frictionlab.data``)."""
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


def available_names() -> list[str]:
    """The built-in datasets and the measured records present beside the repository (``external``)."""
    from . import external

    return builtin_names() + external.present()


#: What a dataset argument may be, for messages.
DATASET_FORMS = "a Dataset, a dataset name or the path to its .toml"


def check_dataset_like(value, where: str, more: tuple = ()) -> None:
    """A TypeError naming ``where`` unless ``value`` is a Dataset, a name or a path (or one of the types ``more``)."""
    if not isinstance(value, (str, os.PathLike, Dataset) + tuple(more)):
        raise TypeError(f"{where}: expected {DATASET_FORMS}, got {type(value).__name__} {value!r:.60}")


@one_blas_thread
def load_dataset(name_or_path: str | Path) -> Dataset:
    """Load and validate a dataset.

    Parameters
    ----------
    name_or_path : str or pathlib.Path or Dataset
        A built-in name (``frictionlab datasets`` lists them), the name of a measured record present beside
        the repository or in ``FRICTIONLAB_RAW_DATA``, or the path of a dataset's TOML file (or its CSV). A
        Dataset is returned as it is.

    Returns
    -------
    Dataset
        SI arrays by column, the scene, the noise, fixed law parameters and the provenance.

    Raises
    ------
    DatasetError
        An unknown name, a file that does not exist, or a file whose content is not a valid dataset (the
        message names the file, the field and what was expected).

    Examples
    --------
    >>> import frictionlab as fl
    >>> data = fl.load_dataset("impact-golf-v28")
    >>> data.kind, data.observable, data.provenance.kind
    ('impact', 'theta', 'reconstructed')
    """
    if isinstance(name_or_path, Dataset):
        return name_or_path
    from . import external

    check_dataset_like(name_or_path, "load_dataset")

    if isinstance(name_or_path, str) and name_or_path in external.RECORDS \
            and not (builtin_dir() / f"{name_or_path}.toml").exists():
        meta, path, raw = external.load(name_or_path)  # a measured record placed beside the repository, not in it
        return from_meta(meta, path, raw=raw)
    path = resolve(name_or_path)
    return from_meta(read_toml(path), path)


def _req(meta, key, path, typ=str):
    if key not in meta:
        raise DatasetError(f"{path}: missing required key '{key}'")
    if not isinstance(meta[key], typ):
        what = {str: "string", dict: "table"}.get(typ, typ.__name__)
        raise DatasetError(f"{path}: '{key}' must be a {what}, got {type(meta[key]).__name__}")
    return meta[key]


def from_meta(meta: dict, path: Path, raw: dict | None = None) -> Dataset:
    """Build a Dataset from a parsed TOML dict whose CSV sits beside ``path`` (``raw``: the CSV's columns,
    already in memory, instead)."""
    name, group, kind, observable, units = _header(meta, path)
    csv = path.with_suffix(".csv")
    raw = read_csv(csv) if raw is None else raw
    columns = _columns(raw, units, path, csv)
    time_zero = _time_origin(meta, columns, raw, kind, path, csv)
    _check_series(columns, raw, kind, csv)
    noise_spec = dict(_table(meta, "noise", path, "[noise]"))
    correlation = _correlation(noise_spec.pop("correlation", "none"), path)
    noise, noise_kind, noise_est, noise_note = noise_table(noise_spec, path, observable, columns, _si_of)
    provenance = _provenance(meta.get("provenance"), path)
    scene = _scene(meta, path, kind, observable, columns, units, csv)
    fixed, fixed_units = _fixed(_table(meta, "fixed", path, "[fixed]"), path)
    reported = _rest(meta, path, provenance)
    return Dataset(name=name, kind=kind, observable=observable, path=path, columns=columns, units=dict(units),
                   noise=noise, scene=scene, fixed=fixed, provenance=provenance,
                   description=meta.get("description", ""), reported=reported,
                   fixed_units=fixed_units, noise_kind=noise_kind, group=group, time_zero=time_zero,
                   noise_df={k: e.df for k, e in noise_est.items()}, noise_est=noise_est, noise_note=noise_note,
                   noise_correlation=correlation,
                   stated=stated_table(_table(meta, "stated", path, "[stated]"), path, kind, noise_kind, _quantity))


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


def _names(columns) -> str:
    """Column names for a one-line message (repr when a name holds odd characters)."""
    return ", ".join(c if c.isprintable() and "," not in c else repr(c) for c in columns)
