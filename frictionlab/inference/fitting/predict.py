"""What is fitted and how a law predicts it: targets, one predictor per dataset kind, solver choice.

``predict(law, target, params, solver, scene, rtol)`` is the single place that turns law parameters
into the model of a dataset's observable. Time-series kinds ('impact', 'incline') simulate and
read a trajectory series; another kind (e.g. 'impact-outcome', whose rows are impacts) plugs in
with ``register_predictor(kind, fn)``. A kind without a predictor is skipped with that reason.
``rtol`` is the ODE tolerance of the prediction (None: ``FIT_RTOL``); it is an argument, never
module state, so fits at different tolerances can run side by side.
"""
from __future__ import annotations


import functools
import inspect
import warnings
from collections.abc import Callable, Mapping

import attrs
import numpy as np

from ...core.errors import DatasetError, FrictionLabError, ParameterError
from ...io.dataset import Dataset, load_dataset
from ...physics.freeable import SCENE_QUANTITIES
from ...physics.registry import get_law
from ...physics.law import FrictionLaw
from ...physics.scene import Scene
from ...solve.outcome import OUTCOMES, predict_outcomes, predict_outcomes_many, rows_of

#: Trajectory series that a time-series observable reads.
SERIES = {"omega": "omega", "theta": "theta", "v": "v", "u": "u", "mu": "load"}

#: Default ODE tolerance of fits (``fit(..., rtol=None)``). The tolerance check of the built-in
#: comparison (``fitcost.tolerance_check``, measured in benchmarks/README) finds that refitting at
#: 1e-10 moves no parameter of an ODE fit by more than a few thousandths of its standard error,
#: for about half the CPU time; 1e-3 moves them by standard errors.
FIT_RTOL = 1e-6


class SkipDataset(FrictionLabError):
    """A dataset this law or solver cannot predict (reported as 'skipped', not 'failed')."""


#: What names a dataset: a loaded Dataset, a built-in name, or the path of its TOML (or CSV).
DatasetLike = "Dataset | str | os.PathLike"

# --- targets: what is fitted -------------------------------------------------------------
@attrs.frozen(eq=False)
class Target:
    """One fitted series (made by `make_target`).

    Attributes
    ----------
    dataset : Dataset
        Where the series comes from.
    observable : str
        The column fitted (``theta``, ``omega``, ``v``, ``mu``, or ``stated`` for a reconstruction's numbers).
    y, sigma : numpy.ndarray
        The values and their 1-sigma noise per point, SI.
    derivation : str
        How ``y`` was derived (e.g. omega from theta by poly9), or "".
    """

    dataset: Dataset
    observable: str
    y: np.ndarray
    sigma: np.ndarray
    derivation: str = ""  # "" or how y was derived (e.g. omega from theta by poly9)

    @property
    def name(self) -> str:
        """The dataset's name."""
        return self.dataset.name

    @property
    def t(self) -> np.ndarray | None:
        """The dataset's time column [s], None for one impact per row."""
        return self.dataset.columns.get("t")

    @property
    def label(self) -> str:
        """'DATASET (observable)', with how it was derived where it was."""
        return f"{self.name} ({self.observable}{', ' + self.derivation if self.derivation else ''})"


def make_target(dataset: DatasetLike, observable: str | None = None, derive: str | None = None) -> Target:
    """The series to fit from a dataset: its observable, another column, or omega derived from theta.

    Parameters
    ----------
    dataset : Dataset, str or path
        The dataset (loaded by `load_dataset` when a name or path).
    observable : str, optional
        The column to fit; default the dataset's observable (a reconstruction's stated numbers).
    derive : {"poly9", "spline"}, optional
        Fit omega, derived from the theta column by this smoother.

    Returns
    -------
    Target
        The values and their noise, SI.

    Raises
    ------
    DatasetError
        No such column, or a column without noise to fit against.

    Examples
    --------
    >>> import frictionlab as fl
    >>> target = fl.make_target("incline-oil-a100")
    >>> target.observable, target.y.shape
    ('v', (101,))
    """
    ds = load_dataset(dataset)
    if ds.kind == "contact-area":
        raise SkipDataset(f"dataset '{ds.name}' is a contact-area series: supporting data, not fitted")
    if ds.noise_kind == "none" and ds.stated and observable in (None, "stated") and not derive:
        names = list(ds.stated)
        return Target(ds, "stated", np.array([ds.stated[k][0] for k in names]),
                      np.array([ds.stated[k][1] for k in names]), "")
    obs = observable or ds.observable
    if derive:
        from ...physics.derive import derive_omega

        if "theta" not in ds.columns:
            raise DatasetError(f"dataset '{ds.name}': deriving omega needs a 'theta' column")
        d = derive_omega(ds.t, ds.columns["theta"], derive, ds.noise.get("theta"))
        return Target(ds, "omega", d.omega, d.sigma, f"omega from theta by {derive}")
    if obs not in ds.columns:
        raise DatasetError(f"dataset '{ds.name}': no column '{obs}' to fit (has: {', '.join(ds.columns)})")
    if obs in ds.noise:
        sigma = np.full(len(ds), ds.noise[obs])
    else:
        raise DatasetError(f"dataset '{ds.name}': [noise] gives no estimate for '{obs}'; add e.g. {obs} = '...'")
    check_values(ds, obs, sigma)
    return Target(ds, obs, ds.columns[obs], sigma)


def check_values(ds, obs: str, sigma) -> None:
    """The values a fit uses, checked where it uses them (a Dataset's arrays and dicts may have been changed
    since the dataset was read and checked): the fitted column and the times finite, the times in order, sigma
    a positive number. A one-line DatasetError naming the dataset and the value otherwise."""
    later = "(changed after the dataset was read?)"
    for col in dict.fromkeys([obs] + (["t"] if "t" in ds.columns else [])):
        bad = np.flatnonzero(~np.isfinite(np.asarray(ds.columns[col], dtype=float)))
        if bad.size:
            raise DatasetError(f"dataset '{ds.name}': column {col} holds a value that is not a finite number in row "
                               f"{bad[0] + 1} {later}")
    if "t" in ds.columns and np.any(np.diff(ds.columns["t"]) < 0):
        raise DatasetError(f"dataset '{ds.name}': column t must not decrease (row "
                           f"{int(np.flatnonzero(np.diff(ds.columns['t']) < 0)[0]) + 2}) {later}")
    s = np.asarray(sigma, dtype=float)
    if not (np.all(np.isfinite(s)) and np.all(s > 0)):
        raise DatasetError(f"dataset '{ds.name}': [noise] {obs} = {ds.noise.get(obs)!r} must be a positive number "
                           f"(SI) {later}")


# --- predictions: one function per dataset kind -------------------------------------------
Predictor = Callable[..., np.ndarray]
PREDICTORS: dict[str, Predictor] = {}


def register_predictor(kind: str, fn: Predictor) -> None:
    """Make a dataset kind fittable by saying how a law predicts its observable.

    Parameters
    ----------
    kind : str
        The dataset kind (``impact``, ``incline``, or a kind of your own).
    fn : callable
        ``fn(law, target, scene, params, solver[, rtol=...])`` returning the model of ``target.y`` (SI) at law
        parameters ``params`` (SI). A predictor that solves ODEs takes the keyword ``rtol`` (always given a
        number).
    """
    PREDICTORS[kind] = fn


@functools.lru_cache(maxsize=None)
def takes_rtol(fn) -> bool:
    """Whether predictor ``fn`` accepts the ``rtol`` keyword."""
    try:
        ps = inspect.signature(fn).parameters.values()
    except (TypeError, ValueError):
        return False
    return any(p.name == "rtol" or p.kind is p.VAR_KEYWORD for p in ps)


#: Points of the grid over the contact on which the stated numbers of a reconstruction are read off
#: (fixed: the prediction must not depend on how densely the reconstruction was sampled).
STATED_GRID = 401


def stated_numbers(tr, contact_time: float) -> dict[str, float]:
    """The numbers a paper states about an impact's spin, read off a trajectory on [0, t_c]: peak spin
    and its time (a parabola through the grid's three highest points), spin at t_c, the largest angle."""
    got = stated_rows(np.asarray(tr.t), np.asarray(tr["omega"])[None], np.asarray(tr["theta"])[None])
    return {k: float(v[0]) for k, v in got.items()}


def stated_rows(t: np.ndarray, omega: np.ndarray, theta: np.ndarray) -> dict[str, np.ndarray]:
    """``stated_numbers`` of each row of ``omega`` and ``theta`` (m, n) [rad/s, rad] on the grid ``t`` (n,) [s]:
    each number an (m,) array."""
    m = omega.shape[0]
    rows = np.arange(m)
    top = np.argmax(omega, axis=1)
    i = np.clip(top, 1, omega.shape[1] - 2)
    y0, y1, y2 = omega[rows, i - 1], omega[rows, i], omega[rows, i + 1]
    den = y0 - 2 * y1 + y2
    curved = den < 0
    with np.errstate(divide="ignore", invalid="ignore"):
        shift = np.clip(np.where(curved, 0.5 * (y0 - y2) / den, 0.0), -1.0, 1.0)
    h = t[1] - t[0]
    return {"omega_peak": np.where(curved, y1 - 0.25 * (y0 - y2) * shift, omega[rows, top]),
            "t_peak": np.where(curved, t[i] + shift * h, t[top]),
            "omega_end": omega[:, -1].copy(), "theta_max": np.max(theta, axis=1)}


def _predict_series(law, target, scene, params, solver, rtol=FIT_RTOL):
    from ...solve.solvers import simulate

    if target.observable == "stated":  # a reconstruction's stated numbers (io.noise.STATED)
        tc = scene.area.contact_time
        tr = simulate(law, scene, params, solver=solver, t=np.linspace(0.0, tc, STATED_GRID), rtol=rtol)
        got = stated_numbers(tr, tc)
        return np.array([got[k] for k in target.dataset.stated])
    if target.observable not in SERIES:
        raise SkipDataset(f"dataset '{target.name}': observable '{target.observable}' is not a simulated series "
                          f"({', '.join(SERIES)})")
    tr = simulate(law, scene, params, solver=solver, t=target.t, rtol=rtol)
    return tr[SERIES[target.observable]]


def outcome_predictor(law, target, scene, params, solver, rtol=FIT_RTOL):
    """Model of an impact-outcome target: the observable outcome per row, SI, row by row through
    ``outcome.predict_outcomes``, ODEs solved to ``rtol``."""
    if target.observable not in OUTCOMES:
        raise SkipDataset(f"dataset '{target.name}': '{target.observable}' is not an impact outcome "
                          f"({', '.join(OUTCOMES)})")
    if target.observable in ("psi1", "psi2") and (scene.materials is None or scene.friction is None):
        raise SkipDataset(f"dataset '{target.name}': {target.observable} needs [scene.materials] with the "
                          "moduli and the stated friction coefficient")
    rows = rows_of(target.dataset)
    return predict_outcomes(law, scene, params, solver, speed=rows["speed"], incidence=rows["incidence"],
                            spin=rows["spin"], rtol=FIT_RTOL if rtol is None else rtol)[target.observable]


register_predictor("impact", _predict_series)
register_predictor("incline", _predict_series)
register_predictor("spring-slider", _predict_series)
register_predictor("impact-outcome", outcome_predictor)


def design(target: Target) -> tuple | None:
    """What a built-in predictor reads from ``target``'s dataset: its kind, the observable, the stated
    numbers' table and every column but the observed one (a resampled copy of the data shares them all); None
    for a kind predicted by a third party's function, which may read anything."""
    ds = target.dataset
    if PREDICTORS.get(ds.kind) not in (_predict_series, outcome_predictor):
        return None
    return (ds.kind, target.observable, ds.stated) + tuple(v for k, v in ds.columns.items() if k != target.observable)


def predict(law: str | FrictionLaw, target: Target, params: Mapping[str, float], solver: str = "exact",
            scene: Scene | None = None, rtol: float | None = None) -> np.ndarray:
    """A law's prediction of a fitted series.

    Parameters
    ----------
    law : str or FrictionLaw
        A registered name or a law.
    target : Target
        The series (`make_target`).
    params : mapping of str to float
        Law parameters, SI.
    solver : str, default "exact"
        ``"exact"``, ``"series"`` or ``"ode[:METHOD]"``.
    scene : Scene, optional
        The scene to solve on; default the dataset's.
    rtol : float, optional
        Tolerance of any ODE solve; None: 1e-6.

    Returns
    -------
    numpy.ndarray
        The model of ``target.y``, SI, one value per point.

    Raises
    ------
    SkipDataset
        No predictor for the dataset's kind.

    Examples
    --------
    >>> import frictionlab as fl
    >>> target = fl.make_target("incline-oil-a100")
    >>> model = fl.predict("couette", target, {"eta": 0.1, "h": 1e-4}, solver="exact")
    >>> model.shape == target.y.shape
    True
    """
    law = get_law(law)
    kind = target.dataset.kind
    if kind not in PREDICTORS:
        raise SkipDataset(f"no predictor for dataset kind '{kind}' (dataset '{target.name}'); "
                          f"known: {', '.join(PREDICTORS)}")
    fn = PREDICTORS[kind]
    kw = {"rtol": FIT_RTOL if rtol is None else rtol} if takes_rtol(fn) else {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # series accuracy warnings are recorded in the result instead
        return np.asarray(fn(law, target, scene or target.dataset.scene, params, solver, **kw), dtype=float)


def predict_many(law, target: Target, params_list, solver: str, scene: Scene | None = None) -> list | None:
    """``predict`` at each parameter set of ``params_list`` (SI) in one vectorized call where the kind offers one
    (``predict_array``); None where it does not, or refuses, and ``predict`` one set at a time gives each answer
    or error."""
    law = get_law(law)
    if not params_list or (scene is not None and scene is not target.dataset.scene):  # the dataset's own scene only
        return None
    try:
        got = predict_array(law, target, params_list, solver)
    except FrictionLabError:
        return None
    return None if got is None else list(got)


def set_scene_quantity(scene: Scene, name: str, value: float) -> Scene:
    """A copy of ``scene`` with the (dotted) quantity ``name`` set to ``value`` (SI)."""
    head, _, tail = name.partition(".")
    if not tail:
        return attrs.evolve(scene, **{head: float(value)})
    sub = getattr(scene, head)
    return attrs.evolve(scene, **{head: attrs.evolve(sub, **{tail: float(value)})})


def has_scene_quantity(scene: Scene, name: str) -> bool:
    """True if ``scene`` has the (dotted) numeric quantity ``name`` (a spring-slider's spring.stiffness, ...)."""
    try:
        get_scene_quantity(scene, name)
    except ParameterError:
        return False
    return True


def get_scene_quantity(scene: Scene, name: str) -> float:
    if name not in SCENE_QUANTITIES:
        raise ParameterError(f"scene quantity '{name}' cannot be freed; choose from {', '.join(SCENE_QUANTITIES)}")
    obj = scene
    for part in name.split("."):
        if obj is None or not hasattr(obj, part):
            raise ParameterError(f"scene quantity '{name}': this scene has no {name.split('.')[0]!r}"
                                 if obj is None else f"scene quantity '{name}': this scene has no {part!r} "
                                 f"({type(obj).__name__})")
        obj = getattr(obj, part)
    if not isinstance(obj, (int, float)):
        raise ParameterError(f"scene quantity '{name}' is not a number on this scene")
    return float(obj)


#: The observables ``predict_array`` reads off a batch of trajectories.
ARRAY_SERIES = ("omega", "theta", "v", "u")


def predict_array(law, target: Target, params, solver: str) -> np.ndarray | None:
    """``predict`` at m parameter sets at once: ``params`` maps law parameters to (m,) arrays [SI], or is a sequence
    of m mappings (``solve.scenebatch.batch_params``; defaults fill the rest); returns the (m, n) predictions of
    ``target.y``, or None where no batched route serves (then ``predict`` one set at a
    time). Served: a built-in law (a third party's force need not broadcast over parameter sets) with the built-in
    series predictor of an impact or incline on its dataset's scene (a series, or a reconstruction's stated numbers
    read off each row as ``stated_numbers`` reads them) or an impact-outcome dataset's outcomes (every set's impacts
    in one batch, ``_outcomes_array``), solved by the closed forms over a batch of
    parameter sets (``solve.batch``, equal to ``simulate(..., 'exact')`` to round-off; tests/test_batchfit.py)
    or by the paper's series. Raises FrictionLabError where the batch cannot be solved (a value outside its
    bounds)."""
    from ...physics.registry import is_third_party
    from ...solve.batch import simulate_batch
    from ...solve.plan import make_plan
    from ...solve.scenebatch import SceneBatch, batch_params, take_params
    from ...solve.solvers import series

    law = get_law(law)
    ds = target.dataset
    m = len(next(iter(params.values()))) if isinstance(params, Mapping) else len(params)
    if ds.kind == "impact-outcome":
        return _outcomes_array(law, target, params, m, solver)
    stated = target.observable == "stated"
    if (is_third_party(law) or ds.kind not in ("impact", "incline") or PREDICTORS.get(ds.kind) is not _predict_series
            or ds.scene is None or not (target.observable in ARRAY_SERIES or stated)
            or solver not in ("exact", "series")):
        return None
    params = batch_params(law, params, m)
    t = np.linspace(0.0, ds.scene.area.contact_time, STATED_GRID) if stated else np.asarray(target.t, dtype=float)
    names = ("omega", "theta") if stated else (SERIES[target.observable],)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if solver == "series":
            plan = make_plan(ds.scene, law)
            p = take_params(params, slice(None), column=True)
            form = series.check(plan, p)
            got = series.curves(plan, form.k, t)
        else:
            res = simulate_batch(law, SceneBatch(ds.scene, {}, m), params, t=t, solver="exact")
            got = {k: getattr(res, k) for k in names}
        curves = [np.broadcast_to(got[k], (m, t.size)) for k in names]
    if stated:  # a reconstruction's stated numbers, read off each row as ``_predict_series`` reads them
        numbers = stated_rows(t, *curves)
        return np.column_stack([numbers[k] for k in ds.stated]).astype(float)
    return np.array(curves[0], dtype=float)


def _outcomes_array(law, target: Target, params, m: int, solver: str) -> np.ndarray | None:
    """``predict_array`` of an impact-outcome target at m parameter sets: every set's impacts in the closed forms
    of one batch (``outcome.predict_outcomes_many``); None where that route does not serve (a solver but 'exact',
    psi1 and psi2, a third party's predictor, one impact, a refusal)."""
    if (solver != "exact" or target.observable not in OUTCOMES or target.observable in ("psi1", "psi2")
            or PREDICTORS.get("impact-outcome") is not outcome_predictor):
        return None
    if isinstance(params, Mapping):
        params = [{k: float(np.broadcast_to(v, (m,))[i]) for k, v in params.items()} for i in range(m)]
    rows = rows_of(target.dataset)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out = predict_outcomes_many(law, target.dataset.scene, list(params), speed=rows["speed"],
                                    incidence=rows["incidence"], spin=rows["spin"])
    return None if out is None else np.array([np.asarray(o[target.observable], dtype=float) for o in out])
