"""Running the stages: one pool, one clock and one progress count around every stage of ``compare``.

A stage is a short function ``stage(comparison, run) -> dict`` that reads the comparison so far and
returns the fields it fills; the runner applies them (``attrs.evolve``), times the stage and keeps the
progress count. A stage marked ``beside`` (the tolerance check) runs in a side thread next to the
stages after it, its refits queued on the same pool, and its fields are applied before ``answer``."""
from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool

import attrs

from ..core.errors import FrictionLabError, ParameterError
from ..core.cluster import executor
from .planning import FitPlan
from .settings import Settings

Progress = Callable[[int, int, str], None]
#: the last tasks of a stage are named in the progress label while they run (a slow fit is not anonymous)
RUNNING_SHOWN = 3


@attrs.define
class Run:
    """What the stages share besides the comparison: the settings, the plan, the pool and the progress."""

    settings: Settings
    plan: FitPlan
    eq_pairs: list
    progress: Progress | None = None
    pool: object = None  # a concurrent.futures executor, or None to run here
    client: object = None  # a dask.distributed Client: the stages' tasks run on its workers instead of a local pool
    total: int = 0
    done: int = 0
    part: bool = False  # one dataset's task of a cluster run (pipeline.perdataset): checks over all fits wait

    def map(self, fn, tasks: Sequence, label: Callable | None = None) -> list:
        """fn over tasks, on the pool if there is one; results in task order. With ``label``, each
        finished task advances the progress count; without, the stage's tasks are not counted."""
        results = [None] * len(tasks)
        if self.pool is not None and len(tasks) > 1:
            futures = {self.pool.submit(fn, t): i for i, t in enumerate(tasks)}
            for fut in as_completed(futures):
                i = futures[fut]
                try:
                    results[i] = fut.result()
                except BrokenProcessPool:  # a worker was killed, or a plugin ended its process (os._exit)
                    what = label(tasks[i]) if label else "a task"
                    raise FrictionLabError(f"compare: a worker process died while running {what} "
                                           "(killed, out of memory, or a law plugin that ends its process)") from None
                if label:
                    running = [label(tasks[j]) for f, j in futures.items() if not f.done()]
                    self.step(label(tasks[i]) + (f"; still running: {', '.join(running)}"
                                                 if 0 < len(running) <= RUNNING_SHOWN else ""))
            return results
        for i, t in enumerate(tasks):
            if label:  # what runs now, for the 'still working' line of a slow task
                self.step(f"running {label(t)}", advance=False)
            results[i] = fn(t)
            if label:
                self.step(label(t))
        return results

    def step(self, label: str, advance: bool = True) -> None:
        """Advance the progress count by one finished item (``advance=False``: only a new label)."""
        self.done += bool(advance)
        if self.progress:
            self.progress(self.done, self.total, label)


@attrs.frozen
class Stage:
    """A named step of the pipeline: ``fn(comparison, run) -> fields``, run when ``wanted(run)``."""

    name: str
    fn: Callable
    wanted: Callable[[Run], bool]
    beside: bool = False  # runs in a side thread next to the following stages (with a pool)


def select(stages: Sequence[Stage], names: Sequence[str] | None) -> list[Stage]:
    """The stages to run, in the pipeline's order: every wanted one (names None) or the ones named."""
    if names is None:
        return list(stages)
    names = (names,) if isinstance(names, str) else tuple(names)
    known = [s.name for s in stages]
    for n in names:
        if n not in known:
            raise ParameterError(f"compare: unknown stage {n!r}; the stages are {', '.join(known)}")
    return [s for s in stages if s.name in names]


def run_stages(comparison, run: Run, stages: Sequence[Stage], forced: bool = False):
    """Run ``stages`` on one pool of ``run.settings.jobs`` workers (or on ``run.client``'s cluster): each stage wanted by the settings (or
    every one given, when ``forced``), timed; returns the comparison with every stage's fields filled."""
    chosen = [s for s in stages if forced or s.wanted(run)]
    timings = dict(comparison.timings)
    with executor(run.settings.jobs, run.client, "compare", warm_worker) as pool:
        run.pool = pool
        side, pending = ThreadPoolExecutor(1), []
        try:
            for stage in chosen:
                if stage.beside and pool is not None and stage is not chosen[-1]:
                    pending.append((stage, side.submit(_timed, stage, comparison, run)))
                    continue
                if stage.name == "answer":  # the verdicts read every other stage's fields
                    comparison = _collect(comparison, pending, timings)
                run.step(f"stage {stage.name} started", advance=False)  # each stage named as it begins
                part, timings[stage.name] = _timed(stage, comparison, run)
                comparison = attrs.evolve(comparison, **part)
            comparison = _collect(comparison, pending, timings)
        except BaseException:  # ^C, SIGTERM, a crash: do not wait for the side thread; the pool is stopped next
            side.shutdown(wait=False, cancel_futures=True)
            raise
        finally:
            run.pool = None
        side.shutdown(wait=True)
    return attrs.evolve(comparison, timings=timings)


def warm_worker() -> None:
    """On a cluster worker, once: the imports every fit and refit needs (lmfit, the fitting modules, numba's
    cached kernel), so that no task pays them."""
    import lmfit  # noqa: F401

    from ..inference.fitting import fit  # noqa: F401
    from ..solve.compiled import available

    available()


def _timed(stage: Stage, comparison, run: Run) -> tuple[dict, float]:
    t0 = time.perf_counter()
    part = stage.fn(comparison, run)
    return part, time.perf_counter() - t0


def _collect(comparison, pending: list, timings: dict):
    while pending:
        stage, future = pending.pop(0)
        part, timings[stage.name] = future.result()
        comparison = attrs.evolve(comparison, **part)
    return comparison
