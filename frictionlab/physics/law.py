"""What a friction law is: parameters with units and bounds, required contact quantities, a force.

Sign convention (stated once, used everywhere): ``force`` returns F, the friction force
resolved along the slip direction and counted positive when it opposes positive slip u.
A body sliding with velocity v obeys  m dv/dt = drive - F.  A law that opposes slip
returns F with the sign of u. The area-rate law's term mu eta' dA/dt changes sign while
the contact unloads (dA/dt < 0); when it outweighs mu N the returned F has the sign
opposite to u, meaning the law pushes the body along its slip (it then does positive work).

Laws with memory (the state contract). A law may carry internal state variables, e.g. LuGre's
bristle deflection z or rate-and-state's theta. It declares them and their time derivatives:

    class MyLaw(FrictionLaw):
        states = (StateSpec("z", "m", 0.0, 1e-5, "bristle deflection"),)   # initial: SI float or "steady"
        def force(self, p, c):  ...  c.state["z"] ...       # arrays like c.u
        def rates(self, p, c):  return {"z": dz/dt}         # unit/s, one array per state, shaped like c.u
        def steady_state(self, p, c): return {"z": ...}    # only when a StateSpec's initial is "steady"

The plan adds the states to its state vector (as "law:z") only for such a law, and the ODE
solver integrates them (default LSODA, which switches to an implicit method where the states are
stiff, as LuGre's are); closed forms (exact, series) and the explicit batch engine do not apply.
Such a law is integrated through zero slip without stick events (its state carries what static
friction there is, as LuGre's bristles do), unless it sets ``jumps_at_zero_slip = True``: then, as
for a memoryless law, slip reaching zero is an event and the contact sticks, its states held, while
the law's force at vanishing slip can hold it (rate-and-state, whose force turns over within
1e-30 m/s of zero). A memoryless law declares nothing of this: ``states`` defaults to ().
"""
from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from typing import ClassVar

import attrs
import numpy as np

from ..core.errors import FrictionLabError, LawError, ParameterError

#: Contact quantities a law may require, with their SI units.
QUANTITIES = {
    "u": "slip velocity [m/s]",
    "N": "normal force [N]",
    "A": "contact area [m^2]",
    "dAdt": "rate of change of contact area [m^2/s]",
    "t": "time since first contact [s]",
    "dmudt": "rate of the friction coefficient d mu/dt [1/s] (a spring-slider's load rate k (V_lp - V))",
}


@attrs.frozen
class ParamSpec:
    """One parameter of a law.

    Attributes
    ----------
    name : str
        The parameter's name, a Python identifier (``lam``, ``mu``, ``Dc``).
    unit : str
        The SI unit of its value (``"Pa s/m"``; ``""`` or ``"-"`` for a dimensionless one).
    default : float
        Its default value [unit], the start of a fit unless one is given.
    lower, upper : float
        The bounds a fit keeps it within [unit].
    scale : float
        Its typical size [unit]: the optimizer works on the value divided by it.
    description : str
        What it is, in a few words (shown by ``frictionlab laws``).
    display : str, default ""
        The unit it is shown in everywhere (reports, summaries, notebook views), e.g. ``"um"`` for a slip
        distance in m; ``""`` shows it in ``unit``.

    Raises
    ------
    LawError
        A name that is not an identifier, a unit pint does not read, or a default outside its bounds.

    Examples
    --------
    >>> from frictionlab import ParamSpec
    >>> ParamSpec("v_s", "m/s", 0.1, 1e-6, 100.0, 0.1, "Stribeck velocity").unit
    'm/s'
    """

    name: str
    unit: str
    default: float
    lower: float
    upper: float
    scale: float
    description: str
    display: str = ""

    def __attrs_post_init__(self):
        if not (self.lower <= self.default <= self.upper):
            raise LawError(f"parameter {self.name}: default {self.default} outside [{self.lower}, {self.upper}]")
        if not (self.scale > 0 and math.isfinite(self.scale)):
            raise LawError(f"parameter {self.name}: scale must be a positive finite number")


@attrs.frozen
class StateSpec:
    """One internal state of a law with memory.

    Attributes
    ----------
    name : str
        The state's name, a Python identifier (``theta``, ``z``).
    unit : str
        The SI unit of its value.
    initial : float or "steady"
        Its value at the start [unit], or ``"steady"``: the law's ``steady_state`` at the initial slip.
    scale : float
        Its typical size [unit]: the ODE solver's tolerances act relative to it.
    description : str
        What it is, in a few words.

    Raises
    ------
    LawError
        A name that is not an identifier, or an initial value that is neither a finite number nor "steady".
    """

    name: str
    unit: str
    initial: float | str
    scale: float
    description: str

    def __attrs_post_init__(self):
        if not (isinstance(self.name, str) and self.name.isidentifier()):
            raise LawError(f"state {self.name!r}: name must be an identifier (letters, digits, underscores)")
        if isinstance(self.initial, str):
            if self.initial != "steady":
                raise LawError(f"state {self.name}: initial must be an SI number or 'steady', got {self.initial!r}")
        elif isinstance(self.initial, bool) or not isinstance(self.initial, (int, float)) \
                or not math.isfinite(self.initial):
            raise LawError(f"state {self.name}: initial must be a finite SI number or 'steady', got {self.initial!r}")
        if isinstance(self.scale, bool) or not isinstance(self.scale, (int, float)) \
                or not (self.scale > 0 and math.isfinite(self.scale)):
            raise LawError(f"state {self.name}: scale must be a positive finite number, got {self.scale!r}")


@attrs.frozen
class Contact:
    """The contact quantities a law's ``force`` and ``rates`` receive, SI arrays at the sample times.

    Attributes
    ----------
    t : numpy.ndarray
        Time [s].
    u : numpy.ndarray
        Slip velocity [m/s].
    N : numpy.ndarray or None
        Normal force [N]; None when the plan did not build it (the law does not require it).
    A : numpy.ndarray or None
        Contact area [m^2], or None.
    dAdt : numpy.ndarray or None
        Rate of change of the contact area [m^2/s], or None.
    state : mapping of str to numpy.ndarray, or None
        A law's internal states by their unprefixed names (None for a memoryless law).
    dmudt : numpy.ndarray or None
        The friction coefficient's rate [1/s], for a law that requires ``"dmudt"`` (Nagata's state law); None
        otherwise.
    """

    t: np.ndarray
    u: np.ndarray
    N: np.ndarray | None = None
    A: np.ndarray | None = None
    dAdt: np.ndarray | None = None
    state: Mapping[str, np.ndarray] | None = None
    dmudt: np.ndarray | None = None


@attrs.frozen
class AreaSlipForm:
    """The form F = k A u, which a law's ``form`` returns to unlock closed-form solutions on half-sine and
    constant-area scenes.

    Attributes
    ----------
    k : float
        The coefficient [Pa s/m] (``lam`` for the wear law, ``eta / h`` for Couette friction).
    """

    k: float  # [Pa s/m]


@attrs.frozen
class NormalAreaRateForm:
    """The form F = sign(u) (a N + c dA/dt), which a law's ``form`` returns to unlock closed forms (while
    the slip keeps its sign).

    Attributes
    ----------
    a : float
        The coefficient of the normal force [-] (``mu``).
    c : float
        The coefficient of the area's rate [N s/m^2] (``mu eta'`` for the area-rate law).
    """

    a: float  # [-]
    c: float  # [N s/m^2]


_PLUGIN_METHODS = ("force", "form", "rates", "steady_state", "initial_states", "__init__")


def _fenced(fn):
    """``fn`` with numpy's error state restored after each call."""
    @functools.wraps(fn)
    def call(*args, **kwargs):
        saved = np.geterr()
        try:
            return fn(*args, **kwargs)
        finally:
            np.seterr(**saved)

    call.__fenced__ = True
    return call


class FrictionLaw:
    """Base class of a friction law: subclass it, set the class attributes and ``force``, and register it
    (`register_law`, or an entry point in group ``frictionlab.laws``).

    Attributes
    ----------
    name : str
        The registered name (``"exp-stribeck"``).
    formula : str
        The force in words and symbols, shown by ``frictionlab laws`` and in reports.
    citation : str
        Where the law comes from.
    params : tuple of ParamSpec
        Its parameters, each with its SI unit, bounds and typical scale.
    requires : frozenset of str
        The contact quantities ``force`` reads, from ``u``, ``N``, ``A``, ``dAdt`` and ``t``.
    ratio_only : tuple of (str, str)
        Parameter pairs that enter the force only through their ratio (``(("eta", "h"),)``).
    states : tuple of StateSpec
        Internal states of a law with memory, integrated with the motion; () for a memoryless law.
    jumps_at_zero_slip : bool
        A law with memory whose force jumps at zero slip: stick events instead of integrating through zero.

    Examples
    --------
    >>> import frictionlab as fl
    >>> law = fl.get_law("coulomb")
    >>> isinstance(law, fl.FrictionLaw), sorted(law.requires)
    (True, ['N', 'u'])
    """

    name: ClassVar[str]
    formula: ClassVar[str]
    citation: ClassVar[str]
    params: ClassVar[tuple[ParamSpec, ...]]
    requires: ClassVar[frozenset[str]]
    #: Parameter groups that enter the force only through their ratio, e.g. (("eta", "h"),).
    ratio_only: ClassVar[tuple[tuple[str, str], ...]] = ()
    #: Internal states of a law with memory (see the module docstring); () for a memoryless law.
    states: ClassVar[tuple[StateSpec, ...]] = ()
    #: A law with memory whose force jumps at zero slip: stick events instead of integrating through zero.
    jumps_at_zero_slip: ClassVar[bool] = False

    def __init_subclass__(cls, **kwargs):
        """A plugin's methods are fenced: numpy's error state (np.seterr) is restored after each call,
        so a plugin that sets it cannot change how the rest of the program computes."""
        super().__init_subclass__(**kwargs)
        if cls.__module__.startswith("frictionlab."):
            return
        for name in _PLUGIN_METHODS:
            fn = cls.__dict__.get(name)
            if callable(fn) and not hasattr(fn, "__fenced__"):
                setattr(cls, name, _fenced(fn))

    def force(self, p: Mapping[str, float], c: Contact) -> np.ndarray:
        """Friction force [N] at each sample of ``c`` for parameters ``p`` (SI floats)."""
        raise NotImplementedError

    def form(self, p: Mapping[str, float]) -> AreaSlipForm | NormalAreaRateForm | None:
        """The law's closed-form family, if it has one (enables the exact and series solvers)."""
        return None

    def rates(self, p: Mapping[str, float], c: Contact) -> Mapping[str, np.ndarray]:
        """d(state)/dt [unit/s] of each state, arrays shaped like ``c.u`` (laws with memory only)."""
        raise NotImplementedError

    def steady_state(self, p: Mapping[str, float], c: Contact) -> Mapping[str, np.ndarray]:
        """The states at steady sliding with the slip of ``c`` (needed when an initial is "steady")."""
        raise NotImplementedError

    # -- helpers shared by every law --------------------------------------------------
    @property
    def param_names(self) -> tuple[str, ...]:
        """The parameters' names, in declaration order."""
        return tuple(s.name for s in self.params)

    def spec(self, name: str) -> ParamSpec:
        """The ParamSpec of parameter ``name``; an unknown name is a ParameterError listing the law's parameters."""
        for s in self.params:
            if s.name == name:
                return s
        raise ParameterError(f"law '{self.name}' has no parameter '{name}' (it has: {', '.join(self.param_names)})")

    def defaults(self) -> dict[str, float]:
        """Each parameter's default value (SI) by name."""
        return {s.name: s.default for s in self.params}

    def resolve(self, values: Mapping[str, object] | None = None) -> dict[str, float]:
        """Defaults overlaid with ``values``, each checked against its bounds. A value is an SI number, a
        quantity string with its unit as on the command line ('1.81e6 Pa s/m', '80 um', '0.3') or a pint
        Quantity; an error names the parameter and the unit it expected."""
        p = self.defaults()
        for name, value in (values or {}).items():
            s = self.spec(name)
            if isinstance(value, (bool, np.bool_)):  # True is not 1 m
                raise ParameterError(f"law '{self.name}': {name} = {value!r} is a boolean, not a number "
                                     f"(SI value in {s.unit or 'plain units'})")
            if not isinstance(value, (int, float, np.floating, np.integer)):
                from ..core.units import as_si

                value = as_si(value, s.unit, f"law '{self.name}': {name}")
            v = float(value)
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
        if not (np.isfinite(np.sum(f)) or np.all(np.isfinite(f))):  # one pass: a finite sum has finite terms
            raise LawError(f"law '{self.name}': force() returned NaN or infinite values for parameters {dict(p)}")
        return f

    @property
    def state_names(self) -> tuple[str, ...]:
        """The internal states' names (empty for a memoryless law)."""
        return tuple(s.name for s in self.states)

    def evaluate_rates(self, p: Mapping[str, float], c: Contact) -> dict[str, np.ndarray]:
        """``rates`` with its output checked: every declared state, arrays of the input's shape, finite."""
        return self._checked_states("rates", self.rates, p, c)

    def initial_states(self, p: Mapping[str, float], c: Contact) -> dict[str, np.ndarray]:
        """Each state's initial value at the contact ``c`` (steady ones from ``steady_state``)."""
        steady = None
        if any(s.initial == "steady" for s in self.states):
            steady = self._checked_states("steady_state", self.steady_state, p, c)
        return {s.name: steady[s.name] if s.initial == "steady" else np.full(np.shape(c.u), float(s.initial))
                for s in self.states}

    def _checked_states(self, what, fn, p, c) -> dict[str, np.ndarray]:
        try:
            out = fn(p, c)
        except FrictionLabError:
            raise
        except NotImplementedError:
            raise LawError(f"law '{self.name}': declares states {list(self.state_names)} but does not define "
                           f"{what}()") from None
        except Exception as exc:
            raise LawError(f"law '{self.name}': {what}() raised {type(exc).__name__}: {exc}") from exc
        if not isinstance(out, Mapping) or set(out) != set(self.state_names):
            got = sorted(out) if isinstance(out, Mapping) else type(out).__name__
            raise LawError(f"law '{self.name}': {what}() must return a mapping with keys {list(self.state_names)}, "
                           f"got {got}")
        shape = np.shape(c.u)
        checked = {}
        for name in self.state_names:
            r = np.asarray(out[name], dtype=float)
            if r.shape != shape:
                if r.ndim != 0:
                    raise LawError(f"law '{self.name}': {what}()['{name}'] has shape {r.shape}, expected {shape}")
                r = np.full(shape, float(r))
            if not np.all(np.isfinite(r)):
                raise LawError(f"law '{self.name}': {what}()['{name}'] is NaN or infinite for parameters {dict(p)}")
            checked[name] = r
        return checked

    def __repr__(self) -> str:
        return f"<law {self.name}: {self.formula}>"


def sign(u: np.ndarray) -> np.ndarray:
    """sign(u) with sign(0) = 0: a law that opposes slip exerts nothing at exact zero slip."""
    return np.sign(u)
