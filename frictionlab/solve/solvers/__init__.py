"""Solvers: ``exact`` (closed forms), ``series`` (the paper's expansion), ``ode`` (solve_ivp).

Every solver returns a ``Trajectory``; ``simulate`` is the one entry point.
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np

from ...core.errors import SceneError, SolverError
from ...physics.registry import get_law
from ...physics.scene import Scene, SceneSource
from .. import quasistatic
from ..plan import make_plan
from . import exact, ode, segments, series
from ...core.fpstate import with_own_errstate

if TYPE_CHECKING:  # annotations only
    from ...physics.law import FrictionLaw
    from ...physics.trajectory import Trajectory

SOLVERS = ("exact", "series", "ode")


def parse_solver(text: str) -> tuple[str, str | None]:
    """'exact', 'series', 'ode' or 'ode:METHOD' -> (name, method)."""
    name, _, method = str(text).partition(":")
    if name not in SOLVERS:
        raise SolverError(f"unknown solver {text!r}; choose exact, series, ode or ode:METHOD "
                          f"(METHOD one of {', '.join(ode.METHODS)})")
    if name != "ode" and method:
        raise SolverError(f"solver {name!r} takes no method; only ode:METHOD does")
    if name == "ode":
        method = method or "LSODA"
        if method not in ode.METHODS:
            raise SolverError(f"unknown ODE method {method!r}; choose one of {', '.join(ode.METHODS)}")
    return name, method or None


@with_own_errstate
def simulate(law: str | FrictionLaw, scene: Scene | SceneSource, params: Mapping[str, object] | None = None,
             solver: str = "ode", t: np.ndarray | None = None, rtol: float = 1e-10, atol: float | None = None,
             n: int = 201) -> Trajectory:
    """Solve a law on a scene: the motion, the friction force and the spin over time.

    Parameters
    ----------
    law : str or FrictionLaw
        A registered name or a law.
    scene : Scene or Dataset
        The experiment; a Dataset's ``[fixed]`` parameters apply and its time column is the default ``t``.
    params : mapping, optional
        Values overriding the law's defaults, each an SI number, a quantity string (``"1.81e6 Pa s/m"``) or a
        pint Quantity.
    solver : str, default "ode"
        ``"exact"`` (closed form), ``"series"`` (the paper's first-order series), ``"ode"`` (LSODA) or
        ``"ode:METHOD"`` (a scipy ``solve_ivp`` method). ``"ode"`` for a built-in rate-and-state law on a
        quasi-static spring-slider integrates the slider in the field's variables.
    t : array_like, optional
        Sample times [s]; default ``n`` points over the scene's duration.
    rtol, atol : float
        The ODE solver's relative and absolute tolerances (``atol`` default: relative to each state's scale).
    n : int, default 201
        Number of sample times when ``t`` is not given.

    Returns
    -------
    Trajectory
        SI arrays: ``t`` [s], ``v`` [m/s], ``u`` (slip) [m/s], ``omega`` [rad/s], ``force`` [N], ...

    Raises
    ------
    SolverError
        The solver does not apply to this law on this scene (no closed form), or the integration failed.
    ParameterError
        An unknown parameter, a value outside its bounds, or a quantity in the wrong unit.

    Examples
    --------
    >>> import frictionlab as fl
    >>> data = fl.load_dataset("impact-golf-v28")
    >>> traj = fl.simulate("wear", data, {"lam": "1.81e6 Pa s/m"}, solver="exact")
    >>> round(traj.omega[-1] * 60 / (2 * 3.14159265))   # spin at the end of contact [rpm]
    10810
    """
    law = get_law(law)
    name = "scene"
    fixed = {}
    if params is not None and not isinstance(params, Mapping):
        raise TypeError(f"simulate: params: expected a mapping of parameter names to values, got "
                        f"{type(params).__name__} {params!r:.40}")
    if not isinstance(scene, Scene) and hasattr(scene, "scene") and hasattr(scene, "fixed"):  # a Dataset
        if hasattr(scene, "check"):
            scene.check("simulate")  # still what loading made of it
        name = f"dataset '{scene.name}'"
        fixed = {k: v for k, v in scene.fixed.items() if k in law.param_names}
        if scene.kind == "impact-outcome":
            raise SceneError(f"dataset '{scene.name}' (impact-outcome) holds one impact per row; simulate its rows "
                             "with frictionlab.solve.outcome.predict_outcomes")
        if scene.scene is None:
            raise SceneError(f"dataset '{scene.name}' ({scene.kind}) has no [scene] to simulate; "
                             "it is a supporting series, not a motion to fit")
        if t is None:
            t = scene.t
        scene = scene.scene
    if not isinstance(scene, Scene):
        raise TypeError(f"simulate: scene: expected a Scene or a Dataset, got {type(scene).__name__} {scene!r:.40}")
    p = law.resolve({**fixed, **(params or {})})
    if t is None:
        t = np.linspace(0.0, scene.duration, n)
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size == 0 or (np.diff(t) < 0).any() or t[0] < 0 or not np.isfinite(t).all():
        raise SolverError("simulate: t must be a non-empty, non-decreasing 1-D array of times >= 0")
    if solver == "ode" and atol is None and not quasistatic.applies(law, scene):  # rate-and-state on a quasi-static slider
        if isinstance(rtol, bool) or not isinstance(rtol, (int, float)) or not 0 < rtol < 1:
            raise SolverError(f"rtol must be a number in (0, 1), got {rtol!r}")
        return quasistatic.simulate(law, scene, p, t, rtol)
    plan = make_plan(scene, law, name)
    kind, method = parse_solver(solver)
    if kind == "series":
        return series.solve(plan, p, t)
    if kind == "exact":
        exact.check(plan, p)
        return segments.run(plan, p, t, exact.make_slide(), "exact")
    return segments.run(plan, p, t, ode.make_slide(method, rtol, atol), f"ode:{method}")
