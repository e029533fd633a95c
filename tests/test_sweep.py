"""Sweeps streamed to disk and reduced per chunk (frictionlab.solve.sweep): the same numbers as one batch,
tables pandas opens, bounded returns, whole-or-nothing output, clear errors."""
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from frictionlab.core.errors import FrictionLabError, SolverError
from frictionlab.solve.batch import SceneBatch, simulate_batch
from frictionlab.solve.sweep import simulate_sweep

from test_batch import oblique

pd = pytest.importorskip("pandas")
pytest.importorskip("pyarrow")


def ends(r):
    """Per-scene reductions: final spin [rad/s] and peak force [N]."""
    return {"final_spin": r.omega[:, -1], "peak_force": r.force.max(axis=1)}


@pytest.fixture()
def sweep_case():
    rng = np.random.default_rng(3)
    batch = SceneBatch.sweep(oblique(40.0, 0.5), {"u0": rng.uniform(2, 30, 11)})
    return batch, {"mu": rng.uniform(0.1, 0.5, 11)}


@pytest.mark.parametrize("threads", [0, 2])
def test_streamed_sweep_equals_one_batch(sweep_case, tmp_path, threads):
    batch, p = sweep_case
    one = simulate_batch("coulomb", batch, p, solver="DOP853", n=41)
    ex = ThreadPoolExecutor(threads) if threads else None
    try:
        sw = simulate_sweep("coulomb", batch, p, solver="DOP853", n=41, chunk=4, out=tmp_path / "s", reduce=ends,
                            executor=ex)
    finally:
        if ex:
            ex.shutdown()
    assert sw.n == 11 and sw.chunks == 3 and sw.path == tmp_path / "s"
    samples = pd.read_parquet(tmp_path / "s" / "samples")
    scenes = pd.read_parquet(tmp_path / "s" / "scenes").set_index("scene")
    assert len(samples) == 11 * 41 and set(samples.columns) >= {"scene", "t", "u", "v", "omega", "theta", "force"}
    for f in ("u", "omega", "force"):
        assert np.array_equal(samples.pivot(index="scene", columns="t", values=f).to_numpy(), getattr(one, f))
    assert np.array_equal(scenes["stick_time"].to_numpy(), one.stick_time, equal_nan=True)
    assert np.array_equal(scenes["final_spin"].to_numpy(), one.omega[:, -1])
    assert np.array_equal(scenes["scene.u0"].to_numpy(), batch.values["u0"])
    assert np.array_equal(scenes["param.mu"].to_numpy(), p["mu"])
    assert np.array_equal(sw.frame()["peak_force"].to_numpy(), one.force.max(axis=1))


def test_reduce_only_keeps_no_samples(sweep_case):
    batch, p = sweep_case
    sw = simulate_sweep("coulomb", batch, p, n=41, chunk=5, reduce=ends)
    assert sw.path is None and set(sw.scenes) == {"scene", "stick_time", "final_spin", "peak_force"}
    assert list(sw.scenes["scene"]) == list(range(11))


def test_fields_choose_the_columns(sweep_case, tmp_path):
    batch, p = sweep_case
    simulate_sweep("coulomb", batch, p, n=21, chunk=6, out=tmp_path / "s", fields=["omega"])
    assert list(pd.read_parquet(tmp_path / "s" / "samples").columns) == ["scene", "t", "omega"]
    with pytest.raises(SolverError, match="unknown field"):
        simulate_sweep("coulomb", batch, p, n=21, out=tmp_path / "t", fields=["spin"])
    assert not (tmp_path / "t").exists()


def test_bad_reduction_and_existing_folder(sweep_case, tmp_path):
    batch, p = sweep_case
    with pytest.raises(SolverError, match="reduction 'x' has shape"):
        simulate_sweep("coulomb", batch, p, n=21, chunk=4, out=tmp_path / "s", reduce=lambda r: {"x": r.u})
    assert not (tmp_path / "s").exists() and not list(tmp_path.iterdir())  # nothing half-written is left
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("keep")
    with pytest.raises(FrictionLabError, match="did not write"):
        simulate_sweep("coulomb", batch, p, n=21, out=tmp_path / "mine", force=True)
    assert (tmp_path / "mine" / "notes.txt").read_text() == "keep"


def test_reductions_keep_no_chunk_alive(sweep_case):
    """A reduction that is a view (omega[:, -1]) is copied where the chunk runs: the per-scene arrays a chunk
    sends back hold none of its samples (a sweep of many chunks would otherwise keep them all)."""
    from frictionlab.solve.sweep import FIELDS, _chunk_task

    batch, p = sweep_case
    job = ("coulomb", batch, p, np.linspace(0.0, batch.template.duration, 41), "auto", 1e-8, None, 41)
    _, per = _chunk_task(0, 0, job, None, lambda r: {"w": r.omega[:, -1]}, FIELDS)
    assert all(a.base is None and a.shape == (11,) for a in per.values())
