"""What a friction law is: parameters with units and bounds, required contact quantities, a force.

Sign convention (stated once, used everywhere): ``force`` returns F, the friction force
resolved along the slip direction and counted positive when it opposes positive slip u.
A body sliding with velocity v obeys  m dv/dt = drive - F.  A law that opposes slip
returns F with the sign of u. The area-rate law's term mu eta' dA/dt changes sign while
the contact unloads (dA/dt < 0); when it outweighs mu N the returned F has the sign
opposite to u, meaning the law pushes the body along its slip (it then does positive work).
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from typing import ClassVar

import attrs
import numpy as np

from .errors import FrictionLabError, LawError, ParameterError

#: Contact quantities a law may require, with their SI units.
QUANTITIES = {
    "u": "slip velocity [m/s]",
    "N": "normal force [N]",
    "A": "contact area [m^2]",
    "dAdt": "rate of change of contact area [m^2/s]",
    "t": "time since first contact [s]",
}


@attrs.frozen
class ParamSpec:
    """One law parameter. ``unit`` is the SI unit of the value; ``scale`` its typical size."""

    name: str
    unit: str
    default: float
    lower: float
    upper: float
    scale: float
    description: str

    def __attrs_post_init__(self):
        if not (self.lower <= self.default <= self.upper):
            raise LawError(f"parameter {self.name}: default {self.default} outside [{self.lower}, {self.upper}]")
        if not (self.scale > 0 and math.isfinite(self.scale)):
            raise LawError(f"parameter {self.name}: scale must be a positive finite number")


@attrs.frozen
class Contact:
    """Contact quantities at sample times, SI arrays; a quantity the plan did not build is None."""

    t: np.ndarray
    u: np.ndarray
    N: np.ndarray | None = None
    A: np.ndarray | None = None
    dAdt: np.ndarray | None = None


@attrs.frozen
class AreaSlipForm:
    """F = k A u. Laws of this form have closed-form solutions on half-sine and constant-area scenes."""

    k: float  # [Pa s/m]


@attrs.frozen
class NormalAreaRateForm:
    """F = sign(u) (a N + c dA/dt). Closed forms exist while slip keeps its sign."""

    a: float  # [-]
    c: float  # [N s/m^2]


class FrictionLaw:
    """Base class of a law plugin. Subclasses set the class attributes and ``force``."""

    name: ClassVar[str]
    formula: ClassVar[str]
    citation: ClassVar[str]
    params: ClassVar[tuple[ParamSpec, ...]]
    requires: ClassVar[frozenset[str]]
    #: Parameter groups that enter the force only through their ratio, e.g. (("eta", "h"),).
    ratio_only: ClassVar[tuple[tuple[str, str], ...]] = ()

    def force(self, p: Mapping[str, float], c: Contact) -> np.ndarray:
        """Friction force [N] at each sample of ``c`` for parameters ``p`` (SI floats)."""
        raise NotImplementedError

    def form(self, p: Mapping[str, float]) -> AreaSlipForm | NormalAreaRateForm | None:
        """The law's closed-form family, if it has one (enables the exact and series solvers)."""
        return None

    # -- helpers shared by every law --------------------------------------------------
    @property
    def param_names(self) -> tuple[str, ...]:
        return tuple(s.name for s in self.params)

    def spec(self, name: str) -> ParamSpec:
        for s in self.params:
            if s.name == name:
                return s
        raise ParameterError(f"law '{self.name}' has no parameter '{name}' (it has: {', '.join(self.param_names)})")

    def defaults(self) -> dict[str, float]:
        return {s.name: s.default for s in self.params}

    def resolve(self, values: Mapping[str, float] | None = None) -> dict[str, float]:
        """Defaults overlaid with ``values``, each checked against its bounds."""
        p = self.defaults()
        for name, value in (values or {}).items():
            s = self.spec(name)
            try:
                v = float(value)
            except (TypeError, ValueError):
                raise ParameterError(f"law '{self.name}': {name} = {value!r} is not a number "
                                     f"(SI value in {s.unit or 'plain units'})") from None
            if not (math.isfinite(v) and s.lower <= v <= s.upper):
                raise ParameterError(
                    f"law '{self.name}': {name} = {value!r} {s.unit} is outside its bounds [{s.lower:g}, {s.upper:g}]"
                )
            p[name] = v
        return p

    def evaluate(self, p: Mapping[str, float], c: Contact) -> np.ndarray:
        """``force`` with its output checked: a float array of the input's shape, finite."""
        try:
            f = np.asarray(self.force(p, c))
        except FrictionLabError:
            raise
        except (Exception, SystemExit) as exc:  # a plugin's exit is its failure, not the program's
            raise LawError(f"law '{self.name}': force() raised {type(exc).__name__}: {exc}") from exc
        if f.dtype.kind not in "fiu":  # complex, bool, object, text: never silently cast to float
            raise LawError(f"law '{self.name}': force() returned {f.dtype} values; expected real floats [N]")
        f = f.astype(float, copy=False)
        if f.shape != np.shape(c.u):
            f = np.broadcast_to(f, np.shape(c.u)) if f.ndim == 0 else f
            if f.shape != np.shape(c.u):
                raise LawError(f"law '{self.name}': force() returned shape {f.shape}, expected {np.shape(c.u)}")
        if not np.all(np.isfinite(f)):
            raise LawError(f"law '{self.name}': force() returned NaN or infinite values for parameters {dict(p)}")
        return f

    def __repr__(self) -> str:
        return f"<law {self.name}: {self.formula}>"


def sign(u: np.ndarray) -> np.ndarray:
    """sign(u) with sign(0) = 0: a law that opposes slip exerts nothing at exact zero slip."""
    return np.sign(u)
