"""frictionlab: compare dynamic sliding friction laws against impact and incline-sliding data.

SI floats inside; units only at the edges (dataset files, command line, reports).
"""
from .dataset import Dataset, load_dataset
from .errors import FrictionLabError
from .law import AreaSlipForm, Contact, FrictionLaw, NormalAreaRateForm, ParamSpec
from .plan import make_plan
from .registry import available_laws, get_law, register_law, unregister_law
from .scene import Scene
from .solvers import simulate
from .trajectory import Trajectory

__version__ = "0.1.0"

__all__ = [
    "AreaSlipForm", "Contact", "Dataset", "FrictionLabError", "FrictionLaw", "NormalAreaRateForm", "ParamSpec",
    "Scene", "Trajectory", "available_laws", "get_law", "load_dataset", "make_plan", "register_law", "simulate",
    "unregister_law",
]
