"""The one result type of every solver."""
from __future__ import annotations

import os
from typing import TYPE_CHECKING

import attrs
import numpy as np

if TYPE_CHECKING:  # annotations only
    import pandas as pd
    from matplotlib.axes import Axes

#: Columns written by ``Trajectory.to_csv``, SI units.
CSV_UNITS = {"t": "s", "u": "m/s", "v": "m/s", "omega": "rad/s", "theta": "rad", "force": "N", "A": "m^2", "N": "N",
             "load": ""}


@attrs.frozen(eq=False)
class Trajectory:
    """Sampled motion, what `simulate` returns; SI arrays.

    Attributes
    ----------
    t : numpy.ndarray
        Time [s].
    u : numpy.ndarray
        Slip velocity at the contact [m/s].
    v : numpy.ndarray
        Body velocity [m/s].
    omega, theta : numpy.ndarray
        Spin [rad/s] and rotation angle [rad]; zero for a body without a spin state.
    force : numpy.ndarray
        Friction force [N].
    A, N : numpy.ndarray or None
        Contact area [m^2] and normal force [N], where the plan built them.
    load : numpy.ndarray or None
        A spring-slider's spring force per unit normal force [-] (the measured friction coefficient).
    law_states : dict of str to numpy.ndarray
        A law's internal states by name (SI, e.g. ``{"z": ...}``); empty for a memoryless law.
    """

    t: np.ndarray
    u: np.ndarray
    v: np.ndarray
    omega: np.ndarray
    theta: np.ndarray
    force: np.ndarray
    A: np.ndarray | None = None
    N: np.ndarray | None = None
    load: np.ndarray | None = None
    solver: str = ""
    law: str = ""
    stick_time: float | None = None  # first time slip reached zero and stuck [s]
    info: dict = attrs.field(factory=dict)  # solver statistics (nfev, method, tolerances, ...)
    law_states: dict = attrs.field(factory=dict)

    def __getitem__(self, name: str) -> np.ndarray:
        name = {"mu": "load"}.get(name, name)  # a spring-slider's observable: the spring's load
        value = getattr(self, name, None)
        if not isinstance(value, np.ndarray):
            raise KeyError(f"trajectory has no series '{name}'")
        return value

    def columns(self) -> dict[str, np.ndarray]:
        """The series by name.

        Returns
        -------
        dict of str to numpy.ndarray
            t, u, v, omega, theta, force, then A, N, load where built, then each law state as ``state_NAME``
            (a rate-and-state 'theta' is ``state_theta``, never the rotation angle); SI.
        """
        out = {k: getattr(self, k) for k in ("t", "u", "v", "omega", "theta", "force")}
        out.update({k: getattr(self, k) for k in ("A", "N", "load") if getattr(self, k) is not None})
        out.update({f"state_{k}": np.asarray(v) for k, v in self.law_states.items()
                    if np.shape(v) == np.shape(self.t)})
        return out

    def to_dataframe(self) -> pd.DataFrame:
        """The columns as a pandas DataFrame.

        Returns
        -------
        pandas.DataFrame
            One column per series (SI; units by column in ``df.attrs['units']``).

        Examples
        --------
        >>> import frictionlab as fl
        >>> traj = fl.simulate("coulomb", fl.load_dataset("impact-golf-v28"), {"mu": 0.3}, solver="exact")
        >>> list(traj.to_dataframe().columns[:6])
        ['t', 'u', 'v', 'omega', 'theta', 'force']
        """
        import pandas as pd

        df = pd.DataFrame(self.columns())
        df.attrs["units"] = {k: CSV_UNITS.get(k, "SI") for k in df.columns}
        return df

    def __repr__(self) -> str:
        n, end = len(self.t), float(self.t[-1]) if len(self.t) else 0.0
        return (f"<Trajectory {self.law or '?'} [{self.solver or '?'}]: {n} times, t = 0 to {end:.4g} s; "
                f"columns {', '.join(self.columns())}"
                + (f"; stuck at {self.stick_time:.4g} s" if self.stick_time is not None else "") + ">")

    def plot(self, y: str = "omega", ax: Axes | None = None, **style: object) -> Axes:
        """Draw one series against time, in display units (rpm for spin, µs or ms for time).

        Parameters
        ----------
        y : str, default "omega"
            A column name: omega, theta, u, v, force, A, N, load, or a law state as ``state_NAME``.
        ax : matplotlib.axes.Axes, optional
            Where to draw; default a new figure's axes.
        **style
            Passed to matplotlib's ``plot`` (color, ls, label, ...).

        Returns
        -------
        matplotlib.axes.Axes
            The axes drawn on.

        Raises
        ------
        KeyError
            ``y`` is not one of the trajectory's columns.
        """
        from ..core.display import axis_label, figure_axes, time_unit, unit

        cols = self.columns()
        if y not in cols and not (y == "mu" and "load" in cols):
            raise KeyError(f"trajectory has no series '{y}'; it has {', '.join(cols)}")
        values = cols[y] if y in cols else cols["load"]
        _, ax = figure_axes(ax, where="Trajectory.plot")
        tname, tf = time_unit(float(self.t[-1]) if len(self.t) else 0.0)
        shown, factor = unit(y)
        style.setdefault("label", f"{self.law} [{self.solver}]")
        ax.plot(self.t * tf, values * factor, **style)
        ax.set_xlabel(f"time [{tname}]")
        ax.set_ylabel(axis_label(y, shown if shown not in ("", "SI") else ("-" if y in ("mu", "load") else "SI")))
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        return ax

    def _repr_html_(self) -> str:
        """A notebook's view: law, solver, times and the columns with their units."""
        import html

        cols = self.columns()
        rows = "".join(f"<tr><td>{html.escape(k)}</td><td>{html.escape(CSV_UNITS.get(k, 'SI') or '-')}</td>"
                       f"<td>{np.min(v):.4g}</td><td>{np.max(v):.4g}</td></tr>" for k, v in cols.items())
        end = float(self.t[-1]) if len(self.t) else 0.0
        stuck = f"; stuck at {self.stick_time:.4g} s" if self.stick_time is not None else ""
        return (f"<p><b>Trajectory</b> {html.escape(self.law or '?')} [{html.escape(self.solver or '?')}]: "
                f"{len(self.t)} times from 0 to {end:.4g} s{html.escape(stuck)}</p>"
                "<table><tr><th>column</th><th>unit (SI)</th><th>min</th><th>max</th></tr>" + rows + "</table>")

    def csv_text(self) -> str:
        """The columns as CSV text.

        Returns
        -------
        str
            A header line, then one row per sample: SI values at full precision (units in ``CSV_UNITS``).
        """
        cols = self.columns()
        rows = np.column_stack(list(cols.values()))
        lines = [",".join(cols)] + [",".join(f"{x:.17g}" for x in row) for row in rows]
        return "\n".join(lines) + "\n"

    def to_csv(self, path: str | os.PathLike) -> None:
        """Write the columns (SI) as CSV, whole or not at all.

        Parameters
        ----------
        path : str or os.PathLike
            The CSV file to write.

        Raises
        ------
        OSError
            The file cannot be written (nothing is left behind).
        """
        from ..core.files import atomic_write_text

        atomic_write_text(path, self.csv_text())
