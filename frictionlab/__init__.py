"""frictionlab: compare dynamic sliding friction laws against impact and incline-sliding data.

SI floats inside; units only at the edges (dataset files, command line, reports).

The names below are imported on first use (module ``__getattr__``), so that ``frictionlab --help``
and a law plugin's ``from frictionlab import FrictionLaw`` do not pay for scipy, lmfit and
matplotlib; ``import frictionlab as fl; fl.fit(...)`` works as if they were imported eagerly.
"""
from __future__ import annotations

import importlib
import sys
import types

__version__ = "0.1.0"

#: public name -> the submodule that defines it
_EXPORTS = {
    "Comparison": "comparison", "compare": "comparison",
    "Dataset": "dataset", "load_dataset": "dataset",
    "derive_omega": "derive",
    "EquivalenceResult": "equivalence", "analyze_equivalence": "equivalence",
    "FrictionLabError": "errors",
    "FitResult": "fitting", "ParamResult": "fitting", "Target": "fitting", "fit": "fitting",
    "make_target": "fitting", "predict": "fitting", "register_predictor": "fitting",
    "AreaSlipForm": "law", "Contact": "law", "FrictionLaw": "law", "NormalAreaRateForm": "law", "ParamSpec": "law",
    "StateSpec": "law",
    "make_plan": "plan",
    "RankRow": "ranking",
    "available_laws": "registry", "get_law": "registry", "register_law": "registry", "unregister_law": "registry",
    "write_report": "report",
    "Scene": "scene",
    "simulate": "solvers",
    "Trajectory": "trajectory",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'frictionlab' has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value  # later look-ups skip this function
    return value


class _Package(types.ModuleType):
    """The package's module type: an exported name that is also a submodule's name (``predict``) stays
    the exported function when that submodule is imported (importing a submodule would otherwise
    rebind the package attribute to it); the submodule itself is in ``sys.modules`` as always."""

    def __setattr__(self, name, value):
        if isinstance(value, types.ModuleType) and name in _EXPORTS and _EXPORTS[name] != name:
            return
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))
