"""Sweeps larger than memory: ``simulate_batch`` chunk by chunk, on an executor, streamed to disk and reduced.

``simulate_sweep(law, scenes, params, ..., executor, chunk)`` alone returns one ``BatchResult`` (the chunks
concatenated in scene order, equal to one call). With ``out`` and/or ``reduce`` nothing the size of the
whole sweep is held: each chunk is simulated, written and reduced where it runs (here, or on an executor's
worker: a concurrent.futures executor or a dask.distributed Client; with ``out`` the workers must see
that folder), and only the reductions come back. ``out`` is a folder written whole or not at all:

  out/samples/part-NNNNN.parquet  long format, one row per scene and sample: scene (int64, the index in
                                  the sweep), t [s], and the fields (default u, v, omega, theta, force,
                                  and A, N where the law reads them), SI
  out/scenes/part-NNNNN.parquet   one row per scene: scene, stick_time [s] (NaN: never stuck), the varied
                                  scene fields and per-scene law parameters, and every reduction

``pandas.read_parquet(out / "samples")`` (or ``/ "scenes"``) opens either table; pyarrow's datasets read
them lazily by column and row group. ``reduce(result) -> {name: (k,) array}`` is called on each chunk's
BatchResult (k scenes) and must be a picklable, module-level function with an executor.
"""
from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import Executor
from pathlib import Path
from typing import TYPE_CHECKING

import attrs
import numpy as np

from ..core.errors import OutputError, SolverError
from ..physics.registry import get_law
from .scenebatch import SceneBatch, batch_params, take_params
from ..core.fpstate import with_own_errstate

if TYPE_CHECKING:  # annotations only
    from ..physics.law import FrictionLaw
    from ..physics.scene import Scene
    from .batch import BatchResult

FIELDS = ("u", "v", "omega", "theta", "force", "A", "N")


@attrs.frozen(eq=False)
class Sweep:
    """What a streamed sweep keeps: n scenes in ``chunks`` chunks; ``scenes`` maps 'scene', 'stick_time' and each
    reduction to an (n,) array; ``path`` the folder written (None without ``out``); solver and law."""

    n: int
    chunks: int
    scenes: dict
    path: Path | None
    solver: str
    law: str

    def frame(self):
        """``scenes`` as a pandas DataFrame indexed by scene."""
        import pandas as pd

        return pd.DataFrame(self.scenes).set_index("scene")


@with_own_errstate
def simulate_sweep(law: str | FrictionLaw, scenes: Sequence[Scene] | SceneBatch,
                   params: Mapping[str, object] | Sequence[Mapping[str, object]] | None = None,
                   t: np.ndarray | None = None, solver: str = "auto", rtol: float = 1e-8, atol: float | None = None,
                   n: int = 201, executor: Executor | None = None, chunk: int = 5000, *,
                   out: str | os.PathLike | None = None,
                   reduce: Callable[[BatchResult], Mapping[str, np.ndarray]] | None = None,
                   fields: Sequence[str] | None = None, force: bool = False) -> Sweep:
    """``simulate_batch`` in chunks of ``chunk`` scenes, dispatched on ``executor`` (None runs here; a
    concurrent.futures executor or a dask.distributed Client spreads the chunks).

    Without ``out`` and ``reduce``: the BatchResult of every scene (equal to one call). With them: a
    ``Sweep``, the chunks written to the folder ``out`` as Parquet (see the module) and/or reduced by
    ``reduce(chunk_result) -> {name: (k,) array}``; fields: the per-sample fields written (default all the
    law has); force: replace an existing ``out`` folder made by frictionlab.
    """
    from .batch import _time_grid

    law = get_law(law)
    batch = scenes if isinstance(scenes, SceneBatch) else SceneBatch.from_scenes(scenes)
    p = batch_params(law, params, batch.n)
    tgrid = _time_grid(batch, t, n)
    chunk = max(1, int(chunk))
    slices = [slice(s, min(s + chunk, batch.n)) for s in range(0, batch.n, chunk)]
    jobs = [(law.name, batch.subset(sl), take_params(p, sl), tgrid if tgrid.ndim == 1 else tgrid[sl], solver, rtol,
             atol, n) for sl in slices]
    if out is None and reduce is None:
        from .batch import simulate_batch

        parts = _map(executor, simulate_batch, jobs)
        return _concat(parts, tgrid)
    fields = _check_fields(fields)
    if out is None:
        return _streamed(law, jobs, slices, executor, None, reduce, fields)
    from ..core.outfolder import atomic_dir

    try:
        import pyarrow.parquet
    except ImportError:
        raise OutputError(f"{out}: writing a sweep to Parquet needs pyarrow: pip install 'frictionlab[parquet]'") from None
    del pyarrow  # imported to fail early, before any work; the chunks import it where they run
    with atomic_dir(out, force=force) as tmp:
        (tmp / "samples").mkdir()
        (tmp / "scenes").mkdir()
        result = _streamed(law, jobs, slices, executor, tmp, reduce, fields)
    return attrs.evolve(result, path=Path(out))


def _check_fields(fields):
    if fields is None:
        return FIELDS
    bad = [f for f in fields if f not in FIELDS]
    if bad:
        raise SolverError(f"simulate_sweep: unknown field(s) {bad}; choose from {', '.join(FIELDS)}")
    return tuple(fields)


def _map(executor, fn, arglists):
    """fn over argument tuples, here or on ``executor``; results in order."""
    if executor is None:
        return [fn(*a) for a in arglists]
    futures = [executor.submit(fn, *a) for a in arglists]
    return [f.result() for f in futures]


def _streamed(law, jobs, slices, executor, folder, reduce, fields) -> Sweep:
    args = [(i, sl.start, job, None if folder is None else str(folder), reduce, fields)
            for i, (sl, job) in enumerate(zip(slices, jobs))]
    parts = _map(executor, _chunk_task, args)
    keys = parts[0][1].keys() if parts else ()
    scenes = {k: np.concatenate([r[k] for _, r in parts]) for k in keys}
    solvers = sorted({s for s, _ in parts})
    return Sweep(n=int(sum(sl.stop - sl.start for sl in slices)), chunks=len(slices), scenes=scenes, path=None,
                 solver="+".join(solvers), law=law.name)


def _chunk_task(i, start, job, folder, reduce, fields):
    """One chunk where it runs: simulated, written (with a folder), reduced; returns (solver, per-scene arrays)."""
    from .batch import simulate_batch

    r = simulate_batch(*job)
    k = len(r)
    per_scene = {"scene": np.arange(start, start + k, dtype=np.int64), "stick_time": np.array(r.stick_time)}
    if reduce is not None:
        for name, v in dict(reduce(r)).items():
            v = np.array(v)  # a copy: a view (omega[:, -1]) would keep the chunk's whole states alive
            if v.shape != (k,):
                raise SolverError(f"simulate_sweep: reduction '{name}' has shape {v.shape}, expected ({k},): one "
                                  "value per scene of the chunk")
            if name in per_scene:
                raise SolverError(f"simulate_sweep: reduction name '{name}' is taken; choose another")
            per_scene[name] = v
    if folder is not None:
        _write_chunk(Path(folder), i, r, job, per_scene, fields)
    return r.solver, per_scene


def _write_chunk(folder: Path, i: int, r, job, per_scene: dict, fields) -> None:
    """The chunk's samples (long) and scenes (one row each, with its inputs) as Parquet files."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    k, m = r.u.shape
    tt = np.broadcast_to(r.t, (k, m))
    cols = {"scene": np.repeat(per_scene["scene"], m), "t": np.ascontiguousarray(tt).reshape(-1)}
    for f in fields:
        a = getattr(r, f)
        if a is not None:
            cols[f] = np.ascontiguousarray(a).reshape(-1)
    pq.write_table(pa.table(cols), folder / "samples" / f"part-{i:05d}.parquet")
    _, batch, params = job[0], job[1], job[2]
    inputs = {f"scene.{name}": v for name, v in batch.values.items()}
    inputs |= {f"param.{name}": np.broadcast_to(v, (k,)) for name, v in params.items()}
    pq.write_table(pa.table({**per_scene, **inputs}), folder / "scenes" / f"part-{i:05d}.parquet")


def _concat(parts, tgrid):
    from .batch import BatchResult

    def cat(name):
        arrs = [getattr(r, name) for r in parts]
        return None if any(a is None for a in arrs) else np.concatenate(arrs, axis=0)

    info = {"chunks": len(parts), "solver_per_chunk": [r.solver for r in parts],
            "nfev": int(sum(r.info.get("nfev", 0) for r in parts))}
    return BatchResult(t=tgrid, u=cat("u"), v=cat("v"), omega=cat("omega"), theta=cat("theta"), force=cat("force"),
                       stick_time=cat("stick_time"), A=cat("A"), N=cat("N"), solver=parts[0].solver, law=parts[0].law,
                       info=info)
