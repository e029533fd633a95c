"""Which fits and tests a comparison makes: candidates (law, solver) per dataset, datasets left out with
one reason, the equivalence pairs, and the pairs too slow to test by default."""
from __future__ import annotations

import re
from collections.abc import Iterable, Sequence

import attrs

from ..core.errors import FrictionLabError
from ..inference.fitting.fit import PREDICTORS, FitResult
from ..solve.choice import applicable_solvers, auto_solver
from ..inference.fitting.predict import has_scene_quantity
from ..inference.verdicts.ranking import family
from ..io.dataset import Dataset
from ..physics.registry import available_laws, get_law


def candidates(law, dataset: Dataset, solvers: Sequence[str] | None) -> list[tuple[str, str | None]]:
    """(solver, reason it does not apply or None) for ``law`` on ``dataset``."""
    law = get_law(law)
    ok = applicable_solvers(law, dataset.scene)
    if solvers is None:
        solver = auto_solver(law, dataset.scene)
        if solver == "ode" and dataset.kind == "impact-outcome" and ok["ode"] is None:
            # every evaluation integrates every impact of the set: minutes per fit for a stateful law
            return [("ode", f"law '{law.name}' has no closed form on impact outcomes, and fitting it with the ODE "
                            "simulates every impact at each evaluation (minutes per fit): name the solver "
                            "(--solver ode) to fit it")]
        out = [(solver, ok["ode"])]
        if ok["series"] is None:
            out.append(("series", None))
        return out
    out = []
    for s in solvers:
        if s == "auto":
            out.append((auto_solver(law, dataset.scene), ok["ode"]))
        else:
            out.append((s, ok.get(s.partition(":")[0])))
    return list(dict.fromkeys(out))  # 'auto' and the solver it picks name one candidate


def no_law_applies(dataset: Dataset, skipped, solvers=None) -> str:
    """The one reason a dataset is left out when no law compared can be fitted to it: the laws grouped by
    why not, and the registered laws that could be (skipped: (law, solver, reason) per candidate)."""
    by_reason: dict[str, list[str]] = {}
    for law, _, why in skipped:
        why = re.sub(rf"^law '{re.escape(law)}' (on an? [\w-]+: )?", "", why)
        why = re.sub(r", which \w+ cannot supply:.*$", ", which it does not have", why)
        by_reason.setdefault(why, [])
        if law not in by_reason[why]:
            by_reason[why].append(law)
    compared = set(law for law, _, _ in skipped)
    able = [n for n in available_laws() if n not in compared
            and any(why is None for _, why in candidates(n, dataset, solvers))]
    which = ("the one law compared does not apply" if len(compared) == 1
             else f"none of the {len(compared)} laws compared applies")
    text = (f"{which} to this {dataset.kind} set ("
            + "; ".join(f"{', '.join(laws)}: {why}" for why, laws in by_reason.items()) + ")")
    return text + (f"; registered laws that apply: {', '.join(able)} (--laws {','.join(able)})" if able else "")


def unique_datasets(dss: Iterable[Dataset]) -> tuple[Dataset, ...]:
    """Datasets with repeats dropped; two different datasets under one name are an error."""
    out: dict[str, Dataset] = {}
    for ds in dss:
        if ds.name in out and out[ds.name].path != ds.path:
            raise FrictionLabError(f"compare: two datasets are named '{ds.name}' ({out[ds.name].path} and {ds.path}); "
                                   "names must be unique")
        out.setdefault(ds.name, ds)
    return tuple(out.values())


@attrs.frozen
class FitPlan:
    """The fits to make (law, dataset, solver, free) and what was decided without fitting."""

    tasks: tuple  # (law, Dataset, solver, free), slowest first
    skipped_fits: tuple[FitResult, ...]  # a candidate whose solver does not apply: a row with the reason
    skipped_datasets: dict  # name -> reason
    no_law: frozenset  # datasets left out because no law compared applies (they get a not-fitted answer)


def plan_fits(law_names: Sequence[str], dss: Sequence[Dataset], solvers, free, by_kind=None) -> FitPlan:
    """Every (law, solver) candidate on every dataset, or the reason a dataset or candidate is left out;
    ``by_kind``: dataset kind -> the laws to fit on it (the default laws), instead of every law on every set."""
    skipped_ds, tasks, fits, no_law = {}, [], [], set()
    for name in free or {}:
        if not any(ds.scene is not None and has_scene_quantity(ds.scene, name) for ds in dss):
            raise FrictionLabError(f"compare --free {name}: none of the datasets' scenes has this quantity")
    for ds in dss:
        if ds.kind == "contact-area":
            skipped_ds[ds.name] = "contact-area series: supporting data (the area model of a scene), not fitted"
            continue
        if ds.kind not in PREDICTORS:
            skipped_ds[ds.name] = f"no predictor for dataset kind '{ds.kind}' yet"
            continue
        names = by_kind.get(ds.kind, law_names) if by_kind else law_names
        mine = [(law, solver, why) for law in names for solver, why in candidates(law, ds, solvers)]
        if mine and all(why for _, _, why in mine):  # nothing to fit: one reason for the dataset, not a row per law
            skipped_ds[ds.name] = no_law_applies(ds, mine, solvers)
            no_law.add(ds.name)
            continue
        for law, solver, why in mine:
            if why:
                fits.append(FitResult(law=law, solver=solver, datasets=(ds.name,), status="skipped", reason=why))
            else:
                tasks.append((law, ds, solver, {k: v for k, v in (free or {}).items()
                                                 if has_scene_quantity(ds.scene, k)}))  # what this scene has
    if len(skipped_ds) == len(dss):
        raise FrictionLabError("compare: none of the datasets can be fitted: "
                               + "; ".join(f"{k}: {v}" for k, v in skipped_ds.items()))
    # slow fits first (ode, then sets without a time series, which simulate every row), so that workers finish together
    tasks.sort(key=lambda x: (not x[2].startswith("ode"), x[1].scene is None or "t" in x[1].columns))
    return FitPlan(tuple(tasks), tuple(fits), skipped_ds, frozenset(no_law))


def equivalence_pairs(law_names, tasks, pairs) -> list[tuple[str, tuple[str, str], tuple[str, str]]]:
    """(dataset, (law A, solver), (law B, solver)) for every pair of ``pairs`` whose laws are both
    fitted on a dataset: each law with its full solver (exact or ode); the paper's pair (the first)
    also with law A's series."""
    names = {get_law(n).name for n in law_names}
    fitted: dict[str, dict[str, list[str]]] = {}
    for law, ds, solver, _ in tasks:
        fitted.setdefault(ds.name, {}).setdefault(law, []).append(solver)
    out = []
    for d, laws in fitted.items():
        for i, (a, b) in enumerate(pairs):
            a, b = get_law(a).name, get_law(b).name
            if not {a, b} <= names or a not in laws or b not in laws:
                continue
            full_a = [s for s in laws[a] if family(s) == "full"]
            full_b = [s for s in laws[b] if family(s) == "full"]
            if not full_b:
                continue
            for sa in full_a + ([s for s in laws[a] if s == "series"] if i == 0 else []):
                out.append((d, (a, sa), (b, full_b[0])))
    return out


def pair_index(pairs, e) -> int:
    """Position of an equivalence result's pair in ``pairs`` (for the report's order)."""
    for i, (a, b) in enumerate(pairs):
        if (get_law(a).name, get_law(b).name) == (e.law_a, e.law_b):
            return i
    return len(pairs)


def slow_pair(fa: FitResult, fb: FitResult, replicates: int) -> str:
    """Why the parametric bootstrap of this pair is slow, or ''."""
    ode = [f for f in (fa, fb) if f.ok and f.solver.startswith("ode")]
    if ode:
        cpu = sum(f.cpu_time for f in ode)
        return (f"{' and '.join(f'{f.law} [{f.solver}]' for f in ode)} need{'s' * (len(ode) == 1)} the ODE solver "
                f"(its fit took {cpu:.1f} CPU s; the test refits both laws up to {4 * replicates} times); add "
                "--bootstrap-all to include it")
    if fa.ok and fa.per_dataset[0].target.t is None:
        return (f"an {fa.per_dataset[0].target.dataset.kind} set simulates every row at each evaluation "
                f"(the test refits both laws up to {4 * replicates} times); add --bootstrap-all to include it")
    return ""
