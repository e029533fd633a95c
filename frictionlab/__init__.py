"""frictionlab: compare dynamic sliding friction laws against impact and incline-sliding data.

SI floats inside; units only at the edges (dataset files, command line, reports).

The names below are imported on first use (module ``__getattr__``), so that ``frictionlab --help``
and a law plugin's ``from frictionlab import FrictionLaw`` do not pay for scipy, lmfit and
matplotlib; ``import frictionlab as fl; fl.fit(...)`` works as if they were imported eagerly.
"""
from __future__ import annotations

import importlib

from .core import __version__  # noqa: F401

#: public name -> the submodule that defines it
_EXPORTS = {
    "Comparison": "pipeline.comparison", "compare": "pipeline.comparison",
    "Dataset": "io.dataset", "load_dataset": "io.dataset",
    "derive_omega": "physics.derive",
    "EquivalenceResult": "inference.equivalence.result", "analyze_equivalence": "inference.equivalence.discrimination",
    "FrictionLabError": "core.errors",
    "FitResult": "inference.fitting.fit", "ParamResult": "inference.fitting.fit", "Target": "inference.fitting.fit",
    "fit": "inference.fitting.fit", "make_target": "inference.fitting.fit", "predict": "inference.fitting.fit",
    "register_predictor": "inference.fitting.fit",
    "AreaSlipForm": "physics.law", "Contact": "physics.law", "FrictionLaw": "physics.law",
    "NormalAreaRateForm": "physics.law", "ParamSpec": "physics.law", "StateSpec": "physics.law",
    "make_plan": "solve.plan",
    "RankRow": "inference.verdicts.ranking",
    "available_laws": "physics.registry", "get_law": "physics.registry", "register_law": "physics.registry",
    "unregister_law": "physics.registry",
    "write_report": "report",
    "Scene": "physics.scene",
    "simulate": "solve.solvers",
    "Trajectory": "physics.trajectory",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'frictionlab' has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value  # later look-ups skip this function
    return value


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))
