"""Running the stages: one pool, one clock and one progress count around every stage of ``compare``.

A stage is a short function ``stage(comparison, run) -> dict`` that reads the comparison so far and
returns the fields it fills; the runner applies them (``attrs.evolve``), times the stage and keeps the
progress count. A stage marked ``beside`` (the tolerance check) runs in a side thread next to the
stages after it, its refits queued on the same pool, and its fields are applied before ``answer``."""
from __future__ import annotations

import threading
import time
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool

import attrs

from ..core.errors import ParameterError, WorkerLost
from ..core.workers import LOST
from ..core.cluster import executor
from ..core.progress import Running
from .planning import FitPlan
from .settings import Settings

Progress = Callable[[int, int, str], None]
#: the last tasks of a stage are named in the progress label while they run (a slow fit is not anonymous)
RUNNING_SHOWN = 3
#: seconds between two labels naming the running tasks while none finishes
TICK = 2.0


@attrs.define
class Run:
    """What the stages share besides the comparison: the settings, the plan, the pool and the progress."""

    settings: Settings
    plan: FitPlan
    eq_pairs: list
    progress: Progress | None = None
    pool: object = None  # a concurrent.futures executor, or None to run here
    client: object = None  # a dask.distributed Client: the stages' tasks run on its workers instead of a local pool
    part: bool = False  # one dataset's task of a cluster run (pipeline.perdataset): checks over all fits wait
    _local: threading.local = attrs.field(factory=threading.local, init=False, repr=False)

    def map(self, fn, tasks: Sequence, label: Callable | None = None) -> list:
        """fn over tasks, on the pool if there is one; results in task order. With ``label``, each
        finished task advances the stage's count, and while none finishes the running ones are named
        with their seconds every TICK seconds (a slow fit in a worker is neither anonymous nor silent)."""
        results = [None] * len(tasks)
        tally = self.tally()
        if label:
            tally.total += len(tasks)
        if self.pool is not None and len(tasks) > 1:
            futures = {self.pool.submit(fn, t): i for i, t in enumerate(tasks)}
            running, pending = Running(len(tasks), self.settings.jobs), set(futures)
            name = (lambda i: label(tasks[i])) if label else None
            if name:
                tally.step(f"{len(tasks)} queued on {self.settings.jobs} workers", advance=False)
            while pending:
                finished, pending = wait(pending, timeout=TICK, return_when=FIRST_COMPLETED)
                for fut in finished:
                    i = futures[fut]
                    results[i] = _result(fut, name(i) if name else "a task")
                    running.finished(i)
                    if name:
                        now = running.now(name, RUNNING_SHOWN)
                        tally.step(name(i) + (f"; running: {now}" if now else ""))
                if name and not finished:
                    tally.step(f"running: {running.now(name, RUNNING_SHOWN)}", advance=False)
            return results
        for i, t in enumerate(tasks):
            if label:  # what runs now, for the 'still working' line of a slow task
                tally.step(f"running {label(t)}", advance=False)
            results[i] = fn(t)
            if label:
                tally.step(label(t))
        return results

    def tally(self) -> "Tally":
        """The count of the stage running in this thread (a stage beside the others has its own)."""
        tally = getattr(self._local, "tally", None)
        if tally is None:
            tally = self._local.tally = Tally("compare", _stage_output(self.progress, "compare"))
        return tally

    def step(self, label: str, advance: bool = True) -> None:
        """Advance this stage's count by one finished item (``advance=False``: only a new label)."""
        self.tally().step(label, advance)

    def begin(self, stage: str) -> None:
        """A stage begins in this thread: a new count, named by the stage."""
        self._local.tally = Tally(stage, _stage_output(self.progress, stage))

    def end(self) -> None:
        tally = getattr(self._local, "tally", None)
        if tally is not None:
            tally.close()
            self._local.tally = None


def _result(fut, what: str):
    try:
        return fut.result()
    except BrokenProcessPool:  # a worker was killed, or a plugin ended its process (os._exit)
        raise WorkerLost(f"compare: a worker process died while running {what} "
                         "(killed, out of memory, or a law plugin that ends its process)") from None


@attrs.define
class Tally:
    """One stage's count: ``out(done, total, label)`` after each finished item (total grows as the
    stage learns of more items)."""

    name: str
    out: Callable | None
    total: int = 0
    done: int = 0

    def step(self, label: str, advance: int = 1) -> None:
        """``advance`` items finished (True: one; False: a new label only)."""
        self.done += int(advance)
        self.total = max(self.total, self.done)
        if self.out:
            self.out(self.done, self.total, label)

    def close(self) -> None:
        if hasattr(self.out, "close"):
            self.out.close()


def _stage_output(progress, stage: str):
    """The stage's own count on a core.progress.Progress (``progress.stage``); on any other callable,
    ``progress(done, total, "STAGE: label")``."""
    if progress is None:
        return None
    if hasattr(progress, "stage"):
        return progress.stage(stage)
    return lambda done, total, label: progress(done, total, f"{stage}: {label}")


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

    from ..inference.fitting.fit import fit  # noqa: F401
    from ..solve.compiled import available

    available()


def _timed(stage: Stage, comparison, run: Run) -> tuple[dict, float]:
    t0 = time.perf_counter()
    run.begin(stage.name)  # each stage counted apart, named as it begins
    try:
        part = stage.fn(comparison, run)
    except BrokenProcessPool:  # --jobs 1: the child process of a third-party law's call (inference.fitting.guard) died
        raise WorkerLost(f"compare: {LOST} in the {stage.name} stage") from None
    except WorkerLost as exc:
        raise WorkerLost(f"{exc} in the {stage.name} stage") from None
    finally:
        run.end()
    return part, time.perf_counter() - t0


def _collect(comparison, pending: list, timings: dict):
    while pending:
        stage, future = pending.pop(0)
        part, timings[stage.name] = future.result()
        comparison = attrs.evolve(comparison, **part)
    return comparison
