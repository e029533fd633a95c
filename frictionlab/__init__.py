"""frictionlab: compare dynamic sliding friction laws against impact and incline-sliding data.

SI floats inside; units only at the edges (dataset files, command line, reports).
"""
from .comparison import Comparison, compare
from .dataset import Dataset, load_dataset
from .derive import derive_omega
from .equivalence import EquivalenceResult, analyze_equivalence
from .errors import FrictionLabError
from .fitting import FitResult, ParamResult, Target, fit, make_target, predict, register_predictor
from .law import AreaSlipForm, Contact, FrictionLaw, NormalAreaRateForm, ParamSpec, StateSpec
from .plan import make_plan
from .ranking import RankRow
from .registry import available_laws, get_law, register_law, unregister_law
from .report import write_report
from .scene import Scene
from .solvers import simulate
from .trajectory import Trajectory

__version__ = "0.1.0"

__all__ = [
    "AreaSlipForm", "Contact", "Dataset", "FrictionLabError", "FrictionLaw", "NormalAreaRateForm", "ParamSpec", "StateSpec",
    "Scene", "Trajectory", "available_laws", "get_law", "load_dataset", "make_plan", "register_law", "simulate",
    "unregister_law",
    # fitting, ranking, comparison, report
    "Comparison", "EquivalenceResult", "FitResult", "ParamResult", "RankRow", "Target", "analyze_equivalence",
    "compare", "derive_omega", "fit", "make_target", "predict", "register_predictor", "write_report",
]
