"""The one result type of every solver."""
from __future__ import annotations

import attrs
import numpy as np

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

    def to_dataframe(self):
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

    def csv_text(self) -> str:
        """The columns (SI, units in CSV_UNITS) as CSV text, full precision."""
        cols = self.columns()
        rows = np.column_stack(list(cols.values()))
        lines = [",".join(cols)] + [",".join(f"{x:.17g}" for x in row) for row in rows]
        return "\n".join(lines) + "\n"

    def to_csv(self, path) -> None:
        """Write the columns (SI) to ``path`` atomically."""
        from ..core.files import atomic_write_text

        atomic_write_text(path, self.csv_text())
