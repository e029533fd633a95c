"""The law registry: entry-point plugins loaded lazily and cached, plus run-time registration.

Built-in and third-party laws arrive the same way, through the ``frictionlab.laws``
entry-point group. ``register_law`` adds one at run time. A plugin that fails to import
(any exception, SystemExit and KeyboardInterrupt included) is skipped with a warning naming
it; two laws under one name is an error naming both. A law is checked when it registers: its
parameters (finite bounds with lower < upper, a default inside them, a positive finite scale,
unique names), its requirements, and a probe of ``force`` (real floats of the input's shape,
opposing slip at the defaults) and ``form``; any failure names the plugin.
"""
from __future__ import annotations

import importlib.machinery
import inspect
import math
import numbers
import warnings
from importlib.metadata import entry_points

import attrs
import numpy as np

from ..core.errors import FrictionLabError, LawError, RegistryError
from ..core.fpstate import own_errstate
from ..core.inputs import note_input
from ..core.names import check_name
from ..core.signals import kept_signals
from .law import (
    QUANTITIES,
    AreaSlipForm,
    Contact,
    FrictionLaw,
    NormalAreaRateForm,
    ParamSpec,
    StateSpec,
)

GROUP = "frictionlab.laws"


class PluginWarning(UserWarning):
    """A law plugin was skipped."""


_laws: dict[str, FrictionLaw] = {}
_sources: dict[str, str] = {}
_runtime: list[tuple[FrictionLaw, str]] = []
_loaded = False
_loading = False


#: Seconds a --load file's import, or a third-party law's check at registration, may take (environment
#: variable FRICTIONLAB_LOAD_TIMEOUT): past it, the process doing it is ended and the load refused.
LOAD_TIMEOUT = 30.0


def load_timeout() -> float:
    """``LOAD_TIMEOUT``, or FRICTIONLAB_LOAD_TIMEOUT when that is a positive number of seconds."""
    import os

    try:
        value = float(os.environ.get("FRICTIONLAB_LOAD_TIMEOUT", ""))
    except ValueError:
        return LOAD_TIMEOUT
    return value if 0 < value < math.inf else LOAD_TIMEOUT


def within_load_limit(fn, *args, what: str, error=RegistryError):
    """``fn(*args)`` tried first in a forked child ended past ``load_timeout()`` seconds (the code it runs
    is not trusted to stop; a plugin's ``except:`` cannot keep the limit), then, if it came back in time,
    run here. Past the limit, or if the child ended without an answer, ``error`` naming ``what``. Inside
    such a child already (a --load file's trial import), it runs here at once."""
    from concurrent.futures.process import BrokenProcessPool

    from ..core import workers

    if workers._beat_fd is None:
        limit = load_timeout()
        try:
            workers.bounded(_tried, limit, fn, *args)
        except workers.OverBudget as exc:
            during = f" during {exc.doing}" if exc.doing else ""
            raise error(f"{what} ran past the load time limit of {limit:g} s (FRICTIONLAB_LOAD_TIMEOUT){during}; "
                        "its process was ended and nothing was loaded") from None
        except BrokenProcessPool:
            raise error(f"{what} ended its process; nothing was loaded") from None
    with kept_signals():  # a plugin that takes SIGINT, SIGTERM or SIGHUP over gives them back
        return fn(*args)


def _tried(fn, *args) -> None:
    """``fn(*args)``, its value dropped (a child's answer unpickled here would import a plugin's module)."""
    fn(*args)


def _as_law(obj, source: str) -> FrictionLaw:
    try:
        law = obj() if inspect.isclass(obj) else obj
    except FrictionLabError:
        raise
    except (Exception, SystemExit) as exc:
        raise LawError(f"law plugin {source}: creating the law raised {type(exc).__name__}: {exc}") from None
    if not isinstance(law, FrictionLaw):
        raise LawError(f"law plugin {source}: {obj!r} is not a frictionlab.FrictionLaw")
    if type(law).__module__.startswith("frictionlab."):
        validate_law(law, source)
    else:  # a third-party law's check runs its code: within the load time limit
        from ..core import workers

        workers.doing(f"the check of law '{getattr(law, 'name', '?')}' at registration (its force, rates and form "
                      "at its defaults)")
        within_load_limit(validate_law, law, source, what=f"law plugin {source}: its check at registration",
                          error=LawError)
        workers.doing("the import")
    return law


def validate_law(law: FrictionLaw, source: str) -> None:
    """Check a law's declaration and probe its force (and, for a law with memory, its rates) with its defaults."""
    for attr in ("name", "formula", "citation", "params", "requires"):
        if not hasattr(law, attr):
            raise LawError(f"law plugin {source}: missing class attribute '{attr}'")
    check_name(law.name, f"law plugin {source}: name", LawError)
    if not isinstance(law.requires, (set, frozenset)) or not all(isinstance(q, str) for q in law.requires):
        raise LawError(f"law '{law.name}' ({source}): requires must be a frozenset of quantity names, "
                       f"got {law.requires!r}")
    unknown = set(law.requires) - set(QUANTITIES)
    if unknown:
        raise LawError(
            f"law '{law.name}' ({source}): requires unknown quantities {sorted(unknown)}; known: {', '.join(QUANTITIES)}"
        )
    if "u" not in law.requires:
        raise LawError(f"law '{law.name}' ({source}): every law must require the slip velocity 'u'")
    _check_params(law, source)
    states = getattr(law, "states", ())
    if not isinstance(states, tuple) or not all(isinstance(x, StateSpec) for x in states):
        raise LawError(f"law '{law.name}' ({source}): states must be a tuple of frictionlab.StateSpec, got {states!r}")
    names = [x.name for x in states]
    if len(set(names)) != len(names):
        raise LawError(f"law '{law.name}' ({source}): state names repeat: {names}")
    n = 5
    probe = Contact(
        t=np.linspace(0.0, 1e-3, n),
        u=np.array([1.0, 0.5, 1e-3, 2.0, 3.0]),
        N=np.full(n, 10.0) if "N" in law.requires else None,
        A=np.full(n, 1e-4) if "A" in law.requires else None,
        dAdt=np.zeros(n) if "dAdt" in law.requires else None,
        dmudt=np.zeros(n) if "dmudt" in law.requires else None,
    )
    p = law.defaults()
    try:
        if states:  # forces at the initial states, and the rates there: finite, one array per state
            probe = attrs.evolve(probe, state=law.initial_states(p, probe))
            law.evaluate_rates(p, probe)
            neg = attrs.evolve(probe, u=-probe.u)
            probe_neg = attrs.evolve(neg, state=law.initial_states(p, attrs.evolve(neg, state=None)))
        else:
            probe_neg = attrs.evolve(probe, u=-probe.u)
        f_pos = law.evaluate(p, probe)
        f_neg = law.evaluate(p, probe_neg)
    except FrictionLabError as exc:  # name the plugin, not only the law
        msg = str(exc)
        prefix = f"law '{law.name}': "
        raise LawError(f"law '{law.name}' ({source}): {msg[len(prefix):] if msg.startswith(prefix) else msg}") from None
    for values in (p, {s.name: s.upper if s.default + s.scale > s.upper else s.default + s.scale for s in law.params}):
        try:
            form = law.form(values)
        except (Exception, SystemExit) as exc:
            raise LawError(f"law '{law.name}' ({source}): form() raised {type(exc).__name__}: {exc}") from None
        if form is not None and not isinstance(form, (AreaSlipForm, NormalAreaRateForm)):
            raise LawError(f"law '{law.name}' ({source}): form() returned {type(form).__name__}; expected None, "
                           "AreaSlipForm or NormalAreaRateForm")
    if np.any(f_pos < 0) or np.any(f_neg > 0):
        raise LawError(
            f"law '{law.name}' ({source}): force() does not oppose slip at its defaults; "
            "frictionlab's convention is F > 0 for u > 0 (m dv/dt = drive - F)"
        )


def _real(x) -> bool:
    return isinstance(x, numbers.Real) and not isinstance(x, bool) and math.isfinite(x)


def _check_params(law: FrictionLaw, source: str) -> None:
    """Refuse a degenerate parameter declaration, naming the plugin and the parameter."""
    where = f"law '{law.name}' ({source})"
    if not isinstance(law.params, (tuple, list)) or not all(isinstance(s, ParamSpec) for s in law.params):
        raise LawError(f"{where}: params must be a tuple of ParamSpec")
    names = [s.name for s in law.params]
    for s in law.params:
        w = f"{where}: parameter {s.name!r}"
        if not isinstance(s.name, str) or not s.name.isidentifier():
            raise LawError(f"{w}: the name must be a Python identifier")
        if names.count(s.name) > 1:
            raise LawError(f"{w} is declared twice")
        if not isinstance(s.unit, str):
            raise LawError(f"{w}: unit must be a string (SI, '' for none)")
        for field in ("default", "lower", "upper", "scale"):
            if not _real(getattr(s, field)):
                raise LawError(f"{w}: {field} = {getattr(s, field)!r} is not a finite real number")
        if not s.lower < s.upper:
            raise LawError(f"{w}: lower bound {s.lower:g} must be below upper bound {s.upper:g} "
                           "(to hold a parameter, fix it in a dataset's [fixed] or with --fix)")
        if not s.lower <= s.default <= s.upper:
            raise LawError(f"{w}: default {s.default:g} is outside its bounds [{s.lower:g}, {s.upper:g}]")
        if not s.scale > 0:
            raise LawError(f"{w}: scale must be positive, got {s.scale:g}")
        if max(abs(s.lower), abs(s.upper)) / s.scale > 1e30 or s.scale / max(abs(s.lower), abs(s.upper)) > 1e30:
            raise LawError(f"{w}: scale {s.scale:g} is out of proportion with the bounds [{s.lower:g}, {s.upper:g}]")


def _add(law: FrictionLaw, source: str) -> None:
    if law.name in _laws and type(_laws[law.name]) is type(law):
        return  # the same class reached twice (a decorator in a module an entry point also names)
    if law.name in _laws:
        raise RegistryError(f"law name '{law.name}' is registered twice: by {_sources[law.name]} and by {source}")
    _laws[law.name] = law
    _sources[law.name] = source


def _load() -> None:
    global _loaded, _loading
    if _loaded or _loading:
        return
    _loading = True
    _laws.clear()
    _sources.clear()
    seen = set()
    try:
        for ep in entry_points(group=GROUP):
            dist = getattr(ep, "dist", None)
            dist_name = f"{dist.metadata['Name']} {dist.version}" if dist is not None else "unknown distribution"
            key = (ep.name, ep.value, dist_name)
            if key in seen:  # the same distribution found twice on sys.path
                continue
            seen.add(key)
            source = f"entry point '{ep.name} = {ep.value}' of {dist_name}"
            try:
                with own_errstate():  # numpy's defaults, whatever a plugin or the caller set; restored after
                    try:
                        obj = (ep.load() if ep.value.startswith("frictionlab.")
                               else within_load_limit(ep.load, what="its import"))
                    except FrictionLabError as exc:  # e.g. a degenerate ParamSpec or StateSpec at import
                        raise LawError(f"law plugin {source}: {exc}") from None
                    law = _as_law(obj, source)
            except FrictionLabError as exc:
                warnings.warn(f"frictionlab: skipped law plugin: {exc}", PluginWarning, stacklevel=3)
                continue
            except (Exception, SystemExit, KeyboardInterrupt) as exc:  # a plugin must not end the program
                warnings.warn(
                    f"frictionlab: skipped law plugin {source}: import failed: {type(exc).__name__}: {exc}",
                    PluginWarning,
                    stacklevel=3,
                )
                continue
            _add(law, source)
        for law, source in _runtime:
            _add(law, source)
    except RegistryError:
        _laws.clear()
        _sources.clear()
        raise
    finally:
        _loading = False
    _loaded = True


def register_law(obj: type[FrictionLaw] | FrictionLaw | None = None, *, replace: bool = False) -> object:
    """Register a law class or instance at run time; usable as a class decorator.

    Registering the same class again (a notebook cell run twice) is a no-op with a warning; a class of the
    same module and name defined anew (the cell edited) replaces the earlier one, with a warning saying so.

    Parameters
    ----------
    obj : type[FrictionLaw] or FrictionLaw, optional
        The law: a subclass of `FrictionLaw` (instantiated without arguments) or an instance. Omitted,
        ``register_law(replace=True)`` returns a decorator.
    replace : bool, default False
        Swap out a law of the same name registered earlier at run time.

    Returns
    -------
    object
        What it was given (the class, when used as a decorator), or a decorator when ``obj`` is omitted.

    Raises
    ------
    RegistryError
        The law is not a valid `FrictionLaw` (a parameter without a unit, an unknown requirement, ...) or its
        name is taken by a built-in or entry-point law, or by a run-time law and ``replace`` is False.

    Examples
    --------
    >>> import numpy as np
    >>> import frictionlab as fl
    >>> @fl.register_law
    ... class Viscous(fl.FrictionLaw):
    ...     name = "viscous-doc"
    ...     formula = "F = c u"
    ...     citation = "a linear damper"
    ...     params = (fl.ParamSpec("c", "N s/m", 1.0, 0.0, 1e6, 1.0, "damping coefficient"),)
    ...     requires = frozenset({"u"})
    ...     def force(self, p, c):
    ...         return p["c"] * c.u
    >>> fl.get_law("viscous-doc").formula
    'F = c u'
    >>> fl.unregister_law("viscous-doc")
    """

    def _register(o):
        source = f"run-time registration of {getattr(o, '__module__', '?')}.{getattr(o, '__qualname__', type(o).__name__)}"
        law = _as_law(o, source)
        _runtime_add(law, source, replace)
        return o

    return _register if obj is None else _register(obj)


def _runtime_add(law: FrictionLaw, source: str, replace: bool) -> None:
    if _loading:  # a plugin module registering itself while entry points load: added after them
        _runtime.append((law, source))
        return
    _load()
    if law.name in _laws and _sources[law.name] == source:  # a notebook cell run again: the same class by name
        if type(_laws[law.name]) is type(law):
            warnings.warn(f"law '{law.name}': {source} again; nothing changed", stacklevel=4)
            return
        warnings.warn(f"law '{law.name}': {source} again; the new definition replaces the earlier one",
                      stacklevel=4)
        replace = True
    if replace and law.name in _laws and _sources[law.name].startswith("run-time"):
        unregister_law(law.name)
    _add(law, source)
    _runtime.append((law, source))


def unregister_law(name: str) -> None:
    """Remove a law registered at run time (entry-point laws stay).

    Parameters
    ----------
    name : str
        The registered name of the law.

    Raises
    ------
    RegistryError
        No law of that name is registered, or it comes from an entry point (a package), not from run time.
    """
    _load()
    if name not in _laws:
        raise RegistryError(f"unknown law '{name}'")
    if not _sources[name].startswith("run-time"):
        raise RegistryError(f"law '{name}' comes from {_sources[name]}; only run-time laws can be removed")
    del _laws[name]
    del _sources[name]
    _runtime[:] = [(law, s) for law, s in _runtime if law.name != name]


def get_law(name: str | FrictionLaw) -> FrictionLaw:
    """The registered law called ``name``.

    Parameters
    ----------
    name : str or FrictionLaw
        A registered name (``frictionlab laws`` lists them); a law instance is returned as it is.

    Returns
    -------
    FrictionLaw
        The law: its parameters (``law.params``, SI units), formula, citation and force.

    Raises
    ------
    RegistryError
        No law of that name is registered (the message lists those that are).

    Examples
    --------
    >>> import frictionlab as fl
    >>> law = fl.get_law("wear")
    >>> [(p.name, p.unit) for p in law.params]
    [('lam', 'Pa s/m')]
    """
    if isinstance(name, FrictionLaw):
        return name
    _load()
    try:
        return _laws[name]
    except KeyError:
        raise RegistryError(f"unknown law '{name}'; registered laws: {', '.join(sorted(_laws))}") from None


def is_third_party(law) -> bool:
    """True for a law whose class is defined outside frictionlab (a plugin, a --load file, a notebook):
    its code is not trusted to stop at a time budget (``inference.fitting.guard``)."""
    return not type(get_law(law)).__module__.startswith("frictionlab.")


def available_laws() -> dict[str, FrictionLaw]:
    """All registered laws by name, in registration order.

    Returns
    -------
    dict of str to FrictionLaw
        The built-in laws, those of installed packages (entry points) and those registered at run time.

    Examples
    --------
    >>> import frictionlab as fl
    >>> {"coulomb", "wear", "area-rate", "couette"} <= set(fl.available_laws())
    True
    """
    _load()
    return dict(_laws)


def law_source(name: str) -> str:
    _load()
    return _sources[get_law(name).name]


def reload_registry() -> None:
    """Forget the cached entry points and read them again (run-time laws are kept)."""
    global _loaded
    _loaded = False
    _load()


def load_law_file(path) -> None:
    """Import a user's Python file by path (laws it registers with @register_law become available).

    Only an existing regular file ending in .py is imported; whatever the import raises (a syntax
    error, sys.exit, KeyboardInterrupt) becomes a one-line RegistryError naming the file.
    """
    import importlib.util
    import os
    import stat
    import sys
    from pathlib import Path

    p = Path(path)
    note_input(p)
    if p.suffix != ".py":
        raise RegistryError(f"--load {path}: expected a Python file ending in .py")
    try:
        mode = os.stat(p).st_mode
    except OSError:
        raise RegistryError(f"--load {path}: no such file") from None
    if not stat.S_ISREG(mode):
        raise RegistryError(f"--load {path}: not a regular file")
    name = f"frictionlab_user_{p.stem}"
    spec = importlib.util.spec_from_file_location(name, p, loader=SourceOnlyLoader(name, str(p)))
    if spec is None or spec.loader is None:
        raise RegistryError(f"--load {path}: cannot be imported as a Python module")
    within_load_limit(_import, spec, path, what=f"--load {path}: importing it (and checking the laws it registers)")


class SourceOnlyLoader(importlib.machinery.SourceFileLoader):
    """The loader of a --load file: it reads the source and writes nothing (a plain loader leaves a __pycache__
    folder beside the user's file wherever Python writes bytecode)."""

    def set_data(self, path, data, **kwargs):  # importlib.abc.SourceLoader's hook that writes the bytecode
        pass


def _import(spec, path) -> None:
    """Import the module of ``spec`` (the --load file ``path``), its errors one line naming the file."""
    import importlib.util
    import sys

    from ..core import workers

    workers.doing("the import")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    try:
        with np.errstate():  # a plugin's np.seterr at import stays in the plugin (restored after)
            spec.loader.exec_module(module)
    except FrictionLabError as exc:
        del sys.modules[spec.name]
        msg = str(exc)
        raise type(exc)(msg if str(path) in msg else f"--load {path}: {msg}") from None
    except (Exception, SystemExit, KeyboardInterrupt) as exc:
        del sys.modules[spec.name]
        what = f"{type(exc).__name__}: {exc}" if str(exc) else type(exc).__name__
        raise RegistryError(f"--load {path}: import failed: {what}") from exc
