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
from importlib import resources
from pathlib import Path

import attrs
import numpy as np

from typing import TYPE_CHECKING

from ..core.errors import DatasetError
from ..core.files import read_toml
from ..physics.scene import Scene
from .csvread import read_csv
from .provenance import PROVENANCE_KINDS, Provenance, _provenance  # noqa: F401  (re-exported)
from .noise import NOISE_KINDS, STATED, noise_table, stated_table  # noqa: F401 (NOISE_KINDS, STATED: read from here too)
from .datasetfields import (COLUMN_SI, _check_series, _columns, _correlation, _fixed, _header, _quantity, _rest,
                            _scene, _si_of, _table, _time_origin)

if TYPE_CHECKING:  # annotations only
    import pandas as pd
    from matplotlib.axes import Axes


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
        _, ax = figure_axes(ax)
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

    if isinstance(name_or_path, str) and name_or_path in external.RECORDS \
            and not (builtin_dir() / f"{name_or_path}.toml").exists():
        meta, path, raw = external.load(name_or_path)  # a measured record placed beside the repository, not in it
        return from_meta(meta, path, raw=raw)
    path = resolve(name_or_path)
    return from_meta(read_toml(path), path)


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
