"""Which solver applies to a law on a scene: the closed form ('exact'), the paper's truncated series ('series')
or the ODE ('ode'), and the one a fit uses when none is named ('auto')."""
from __future__ import annotations

from ..core.errors import FrictionLabError
from ..physics.registry import get_law
from ..physics.scene import Scene


def applicable_solvers(law, scene: Scene) -> dict[str, str | None]:
    """For 'exact', 'series' and 'ode': None if it applies to ``law`` on ``scene``, else why not."""
    from .plan import make_plan
    from .solvers import exact, series

    law = get_law(law)
    if hasattr(scene, "example"):  # an impact-outcome template: check on one of its impacts
        if getattr(scene.compliance, "model", None) == "mindlin-deresiewicz":
            from .outcome import mdr_solvers

            return mdr_solvers(law)
        scene = scene.example()
    try:
        plan = make_plan(scene, law)
    except FrictionLabError as exc:
        return {name: str(exc) for name in ("exact", "series", "ode")}
    out = {"ode": None}
    for name, module in (("exact", exact), ("series", series)):
        try:
            for p in (law.defaults(), _generic_params(law)):  # forms may degenerate at defaults (eta' = 0)
                module.check(plan, p)
            out[name] = None
        except FrictionLabError as exc:
            out[name] = str(exc)
    return out


def _generic_params(law) -> dict[str, float]:
    p = {}
    for s in law.params:
        v = s.default + s.scale
        p[s.name] = v if v <= s.upper else s.default - s.scale
    return p


def auto_solver(law, scene: Scene) -> str:
    """'exact' where a closed form exists for this law and scene, else 'ode'."""
    return "exact" if applicable_solvers(law, scene)["exact"] is None else "ode"
