"""``compare`` on a Dask cluster in coarse tasks: one task per dataset.

A dataset's fits, its equivalence tests, what accuracy costs on it and its bootstrap need nothing but that
dataset's own fits, so one task on one worker runs those stages for it (``--jobs 1`` there) and sends back only their results (fit
rows, test and bootstrap records: tens of kB). The stages across datasets (rank, transfer, tolerance,
answer) then run as they do locally. Compared with one task per fit, test and bootstrap batch: one round
trip per dataset, no barrier between one dataset's fits and another's tests (a worker never waits for the
slowest fit of a stage), and the client idle meanwhile. The same numbers as the local run: every random
stream is keyed by the dataset (and pair), and the parts are merged in the local run's order
(``tests/test_cluster.py``). On a cluster, the time of a per-dataset stage is the sum over its tasks.
"""
from __future__ import annotations

import time
from concurrent.futures import as_completed

import attrs

from ..core.cluster import executor
from ..inference.cost.accuracy import study_fits
from ..inference.resampling.ranking_bootstrap import bootstrap_fits
from .runner import Run, run_stages, warm_worker
from .stages import check_some_fit, equivalence_order, family_adjusted, fit_order

#: The stages one dataset's task runs (in this order); the others run after the parts are merged.
PER_DATASET = ("fit", "equivalence", "accuracy", "bootstrap")


def run_per_dataset(c, run: Run, chosen: list) -> tuple[object, list]:
    """(``c`` with the fields of the chosen PER_DATASET stages filled from one task per dataset on
    ``run.client``'s workers, the chosen stages left to run)."""
    mine = [s for s in chosen if s.name in PER_DATASET]
    tasks, pairs = {}, {}
    for t in run.plan.tasks:  # slowest first: the datasets whose fits are slowest are sent first
        tasks.setdefault(t[1].name, []).append(t)
    for p in run.eq_pairs:
        pairs.setdefault(p[0], []).append(p)
    boot = any(s.name == "bootstrap" for s in mine)
    parts, timings = [], dict(c.timings)
    run.begin(", ".join(s.name for s in mine) + " per dataset")  # one count: a dataset's items as it finishes
    try:
        run.tally().total += sum(len(ts) + len(pairs.get(name, [])) + boot for name, ts in tasks.items())
        with executor(1, run.client, "compare", warm_worker) as ex:
            futures = {ex.submit(_one_dataset, *_part(c, run, name, ts, pairs.get(name, []), mine)): name
                       for name, ts in tasks.items()}
            run.step(f"{len(futures)} dataset{'s' * (len(futures) != 1)} sent to the cluster", advance=False)
            for fut in as_completed(futures):
                part, took = fut.result()
                parts.append(part)
                for k, v in took.items():
                    timings[k] = timings.get(k, 0.0) + v
                name = futures[fut]
                items = len(tasks[name]) + len(pairs.get(name, [])) + boot
                run.step(f"{name}: fits, tests and bootstrap", advance=items)
        fields = _merge(c, run, parts, set(tasks), {s.name for s in mine})
    finally:
        run.end()
    return attrs.evolve(c, **fields, timings=timings), [s for s in chosen if s.name not in PER_DATASET]


def _part(c, run: Run, name: str, tasks: list, pairs: list, stages: list) -> tuple:
    """The arguments of one dataset's task: its comparison so far, its settings (one process there), plan,
    pairs and stages (a Run is made there: its per-thread progress state does not travel)."""
    sub_c = attrs.evolve(c, datasets=tuple(d for d in c.datasets if d.name == name),
                         fits=tuple(f for f in c.fits if f.datasets[0] == name), timings={})
    return (sub_c, attrs.evolve(run.settings, jobs=1), attrs.evolve(run.plan, tasks=tuple(tasks)), pairs,
            tuple(s.name for s in stages))


def _one_dataset(c, settings, plan, pairs: list, names: tuple) -> tuple[dict, dict]:
    """On a worker: the stages ``names`` for one dataset; (the fields they fill, their wall seconds)."""
    from .stages import STAGES

    started = time.perf_counter()
    run = Run(settings=settings, plan=plan, eq_pairs=pairs, part=True)
    done = run_stages(c, run, [s for s in STAGES if s.name in names], forced=True)
    fields = {"fits": done.fits, "equivalence": done.equivalence, "accuracy": done.accuracy,
              "bootstrap": done.bootstrap, "bootstrap_skipped": done.bootstrap_skipped}
    return fields, done.timings or {"per dataset": time.perf_counter() - started}


def _merge(c, run: Run, parts: list, sent: set, names: set) -> dict:
    """The parts' fields in the local run's order; datasets with nothing to fit as the local stages leave them."""
    order = {d.name: i for i, d in enumerate(c.datasets)}
    fields = {}
    if "fit" in names:
        rest = [f for f in c.fits if f.datasets[0] not in sent]
        fields["fits"] = tuple(sorted(rest + [f for p in parts for f in p["fits"]], key=fit_order(c)))
        check_some_fit(fields["fits"])
    if "equivalence" in names:
        found = [e for p in parts for e in p["equivalence"]]
        fields["equivalence"] = family_adjusted(c, sorted(found, key=equivalence_order(c, run.settings.pairs)),
                                                run.settings)
    if "accuracy" in names:  # in the order of the local run: its study's fits (accuracy.study_fits), rows kept together
        rank = {(f.datasets[0], f.law): i for i, f in enumerate(study_fits(fields.get("fits", c.fits)))}
        rows = [r for p in parts for r in p["accuracy"]]
        fields["accuracy"] = tuple(sorted(rows, key=lambda r: rank.get((r.dataset, r.law), len(rank))))
    if "bootstrap" in names:
        s = run.settings
        rest = [f for f in fields.get("fits", c.fits) if f.datasets[0] not in sent]  # nothing fitted there
        boots, skipped = bootstrap_fits(rest, s.bootstrap, s.seed, None, s.bootstrap_all, s.free or None,
                                        timeout=s.fit_timeout,
                                        progress=lambda name, k, n: run.step(f"bootstrap on {name}: left out",
                                                                             advance=k == n))
        boots += [b for p in parts for b in p["bootstrap"]]
        for p in parts:
            skipped.update(p["bootstrap_skipped"])
        fields["bootstrap"] = tuple(sorted(boots, key=lambda b: order[b.datasets[0]]))
        fields["bootstrap_skipped"] = dict(sorted(skipped.items(), key=lambda kv: order[kv[0]]))
    return fields
