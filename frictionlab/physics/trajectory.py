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
    """Sampled motion: time t [s], slip u [m/s], body velocity v [m/s], spin omega [rad/s],
    rotation angle theta [rad], friction force [N], and contact area A [m^2] and normal force
    N [N] where the plan built them. A body without a spin state has omega = theta = 0.
    ``load`` is a spring-slider's spring force per unit normal force [-] (the measured friction coefficient).
    ``law_states`` holds a law's internal states by name (SI, e.g. {"z": ...}); empty for a memoryless law.
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
        """The series by name (SI): t, u, v, omega, theta, force, then A, N, load where built, then each
        law state as ``state_NAME`` (a rate-and-state 'theta' is ``state_theta``, never the rotation angle)."""
        out = {k: getattr(self, k) for k in ("t", "u", "v", "omega", "theta", "force")}
        out.update({k: getattr(self, k) for k in ("A", "N", "load") if getattr(self, k) is not None})
        out.update({f"state_{k}": np.asarray(v) for k, v in self.law_states.items()
                    if np.shape(v) == np.shape(self.t)})
        return out

    def to_dataframe(self) -> pd.DataFrame:
        """The columns as a pandas DataFrame (SI; units by column in ``df.attrs['units']``)."""
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
        """Draw the series ``y`` (a column name: omega, theta, u, v, force, A, N, load, or a law state as
        ``state_NAME``) against time on ``ax`` (a new figure if None), in display units; returns the Axes.
        ``style`` goes to matplotlib's ``plot`` (color, ls, label ...)."""
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
        """The columns (SI, units in CSV_UNITS) as CSV text, full precision."""
        cols = self.columns()
        rows = np.column_stack(list(cols.values()))
        lines = [",".join(cols)] + [",".join(f"{x:.17g}" for x in row) for row in rows]
        return "\n".join(lines) + "\n"

    def to_csv(self, path: str | os.PathLike) -> None:
        """Write the columns (SI) to ``path`` atomically."""
        from ..core.files import atomic_write_text

        atomic_write_text(path, self.csv_text())
