"""What accuracy costs: each solver's error and time against the most accurate one, per law and dataset.

``solver_costs(fit, full=False)`` takes a law's best fit to one dataset and, at its fitted parameters (scene
quantities included), predicts the fitted observable with every solver that applies: the closed form
('exact'), the truncated series ('series'), and the ODE solver at each of RTOLS (FIT_RTOL, the tolerance of
every fit, among them). The most accurate solver is the reference: the closed form where one exists, else the
ODE at REFERENCE_RTOL. Per solver: the RMS difference from the reference in the observable's unit (stated
numbers: in stated precisions) and in units of the data's noise sigma, and the CPU seconds of one prediction
(the thread's CPU time over at least MIN_TIME seconds of repeats, after one untimed prediction of the reference
and of each other kind of solver), with its ratio to the reference's.

It runs by default where it is cheap: a prediction with the fit's own solver costs the fit's CPU time over its
model evaluations; where that, times the solves the study needs (COST_FACTOR), exceeds BUDGET CPU seconds, one
prediction is timed instead (a fit's time may include a kernel compiled once per machine), and where that too
exceeds it the row says so with the estimate and the command that runs it (``frictionlab compare --tolerance``,
which asks for the full study).
"""
from __future__ import annotations

import math
import time

import attrs
import numpy as np

from ...core.errors import FrictionLabError
from ...solve.choice import applicable_solvers
from ..fitting.predict import FIT_RTOL, predict

#: ODE tolerances compared (FIT_RTOL, the fits' own, among them), and the reference's where no closed form exists
RTOLS = (1e-3, FIT_RTOL, 1e-9)
REFERENCE_RTOL = 1e-12
#: CPU seconds a (law, dataset) study may cost by default; COST_FACTOR: its solves in units of one evaluation of
#: the fit's own solver (tight ODE tolerances cost several evaluations each, and each solver is timed repeatedly)
BUDGET = 2.0
COST_FACTOR = 60
MIN_TIME = 0.001  # seconds of repeats a timing covers at least (thread CPU clock: microsecond resolution)
MAX_REPEATS = 50
COMMAND = "frictionlab compare --tolerance"


@attrs.frozen
class SolverCost:
    """One solver on one (law, dataset): its error against the reference solver and its time (SI)."""

    dataset: str
    law: str
    solver: str  # 'exact', 'series', 'ode' (with rtol)
    rtol: float = math.nan  # the ODE tolerance (nan for closed forms and the series)
    reference: bool = False  # the most accurate solver of this row's law and dataset
    error: float = math.nan  # RMS difference from the reference (observable SI; 'stated': stated precisions)
    error_sigma: float = math.nan  # ... in units of the data's noise sigma
    time_s: float = math.nan  # CPU seconds per prediction
    time_ratio: float = math.nan  # time over the reference's
    observable: str = ""
    status: str = "ok"  # ok | not run | failed
    reason: str = ""

    @property
    def label(self) -> str:
        return f"ode rtol {self.rtol:.0e}".replace("e-0", "e-") if self.solver == "ode" else self.solver

    def as_dict(self) -> dict:
        return attrs.asdict(self) | {"label": self.label}


def _timed(law, target, params, solver, scene, rtol, warm: bool = False) -> tuple[np.ndarray, float]:
    """(prediction, CPU seconds per prediction) over at least MIN_TIME seconds of repeats, after one untimed
    prediction unless ``warm`` (a first call may compile a kernel or fill a cache: a one-time cost, not the
    solver's; the ODE at a later tolerance shares the first one's kernel and caches, so ``solver_costs`` warms the
    reference and each other kind of solver once)."""
    if not warm:
        predict(law, target, params, solver, scene=scene, rtol=rtol)
    start, n = time.thread_time(), 0
    while True:
        y = predict(law, target, params, solver, scene=scene, rtol=rtol)
        n += 1
        spent = time.thread_time() - start
        if spent >= MIN_TIME or n >= MAX_REPEATS:
            return y, spent / n


def _evaluation_cost(fit) -> float:
    """CPU seconds of one prediction by the fit's own solver at its parameters (after one untimed prediction), or
    infinity where it fails."""
    d = fit.per_dataset[0]
    try:
        return _timed(fit.law, d.target, d.params, fit.solver, d.scene, None)[1]
    except FrictionLabError:
        return math.inf


def solver_costs(fit, full: bool = False) -> tuple[SolverCost, ...]:
    """The study for one fit (module docstring): reference first, then the others; a single 'not run' row where
    it is not cheap and ``full`` is False."""
    d = fit.per_dataset[0]
    target, scene, law, name = d.target, d.scene, fit.law, fit.datasets[0]
    base = dict(dataset=name, law=law, observable=target.observable)
    estimate = fit.cpu_time / max(fit.nfev, 1) * COST_FACTOR
    if not full and estimate > BUDGET:  # the fit's time may hold one-time costs (a kernel compiled): time one
        estimate = _evaluation_cost(fit) * COST_FACTOR
    if not full and estimate > BUDGET:
        return (SolverCost(**base, solver="all", status="not run",
                           reason=f"about {estimate:.0f} CPU s here, more than the {BUDGET:g} s a default run allows; "
                                  f"`{COMMAND}` runs it"),)
    ok = applicable_solvers(law, scene)
    todo = ([("exact", None)] if ok.get("exact") is None else []) + [("ode", r) for r in RTOLS]
    if ok.get("series") is None:
        todo.insert(1, ("series", None))
    ref = ("exact", None) if ok.get("exact") is None else ("ode", REFERENCE_RTOL)
    sigma = np.asarray(target.sigma, dtype=float)
    noise = 1.0 if target.observable == "stated" else float(np.sqrt(np.mean(sigma ** 2)))
    scale = sigma if target.observable == "stated" else 1.0
    try:
        y_ref, t_ref = _timed(law, target, d.params, ref[0], scene, ref[1])
    except FrictionLabError as exc:
        return (SolverCost(**base, solver=ref[0], status="failed", reason=str(exc)),)
    out = [SolverCost(**base, solver=ref[0], rtol=ref[1] if ref[1] else math.nan, reference=True, error=0.0,
                      error_sigma=0.0, time_s=t_ref, time_ratio=1.0)]
    warmed: set = set()  # the kinds of solver called here: an ODE tolerance after the first shares its kernel
    for solver, rtol in todo:
        if (solver, rtol) == ref:
            continue
        try:
            y, t = _timed(law, target, d.params, solver, scene, rtol, warm=solver in warmed)
            warmed.add(solver)
        except FrictionLabError as exc:
            out.append(SolverCost(**base, solver=solver, rtol=rtol or math.nan, status="failed", reason=str(exc)))
            continue
        err = float(np.sqrt(np.mean(((y - y_ref) / scale) ** 2)))
        out.append(SolverCost(**base, solver=solver, rtol=rtol if rtol else math.nan, error=err,
                              error_sigma=err / noise if noise > 0 else math.nan, time_s=t,
                              time_ratio=t / t_ref if t_ref > 0 else math.nan))
    return tuple(out)


def study_fits(fits) -> list:
    """The fits the study runs on: per dataset and law, the one whose parameters it uses (the exact or ODE fit,
    else the series fit), single-dataset fits that succeeded."""
    chosen: dict = {}
    for f in fits:
        if not f.ok or len(f.datasets) != 1:
            continue
        key = (f.datasets[0], f.law)
        if key not in chosen or (chosen[key].solver == "series" and f.solver != "series"):
            chosen[key] = f
    return list(chosen.values())


def _num(x: float) -> str:
    return f"{x:.2g}"


def _ratios(rows) -> str:
    lo, hi = min(r.time_ratio for r in rows), max(r.time_ratio for r in rows)
    return f"{_num(lo)}×" if _num(lo) == _num(hi) else f"{_num(lo)}–{_num(hi)}×"


def _ratio(rows) -> str:
    """The largest time ratio, two figures ('4.8×')."""
    return f"{_num(max(r.time_ratio for r in rows))}×"


def group_texts(rows) -> tuple[str, str]:
    """(sentences, a few words) of what accuracy costs over one group's rows: per solver its largest error in
    noise sigmas against the reference and its time over the reference's."""
    ok = [r for r in rows if r.status == "ok" and not r.reference]
    skipped = [r for r in rows if r.status == "not run"]
    if not ok:
        if skipped:
            return (f"Not run: {skipped[0].reason}.", f"not run ({skipped[0].reason.split(',')[0]}): `{COMMAND}`")
        return "", ""
    refs = sorted({r.label for r in rows if r.reference})
    ref_text = " or ".join("the closed form" if x == "exact" else f"the ODE at {x.removeprefix('ode ')}" for x in refs)
    labels = list(dict.fromkeys(r.label for r in ok))
    parts, short = [], []
    for label in labels:
        mine = [r for r in ok if r.label == label]
        worst = max(mine, key=lambda r: r.error_sigma)
        what = ("the truncated series" if label == "series" else f"the ODE at {label.removeprefix('ode ')}"
                + (" (the fits' own tolerance)" if label == f"ode rtol {FIT_RTOL:.0e}".replace("e-0", "e-") else ""))
        parts.append(f"{what} is off by at most {_num(worst.error_sigma)}σ ({worst.law} on {worst.dataset}) at "
                     f"{_ratios(mine)} the reference's time")
        if label == "series" or label.endswith(f"{FIT_RTOL:.0e}".replace("e-0", "e-")):
            short.append(f"{'ode' if label != 'series' else label} ≤ {_num(worst.error_sigma)}σ at {_ratio(mine)}")
    text = (f"Against {ref_text} (the most accurate solver), at each law's fitted parameters, in units of the "
            f"noise σ (stated precisions for stated numbers): " + "; ".join(parts) + ".")
    if skipped:
        text += f" Not run on {', '.join(sorted({r.dataset for r in skipped}))}: {skipped[0].reason}."
    short.sort(key=lambda x: not x.startswith("series"))
    return text, ("vs " + ("exact" if refs == ["exact"] else "/".join(r.replace("ode rtol ", "ode ") for r in refs))
                  + ": " + "; ".join(short)) if short else ""


def fill_answers(answers, rows) -> tuple:
    """``answers`` (answers.Answer) with ``accuracy`` and its short form filled from the study's ``rows``."""
    out = []
    for a in answers:
        mine = [r for r in rows if r.dataset in a.datasets]
        text, short = group_texts(mine)
        out.append(attrs.evolve(a, accuracy=text, short={**a.short, **({"accuracy": short} if short else {})}))
    return tuple(out)
