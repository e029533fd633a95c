"""Compare on a Dask cluster (LocalCluster, worker processes): the same numbers as the local run whatever the
number of workers, the report's figures drawn there, and the command's one-line error for a bad scheduler."""
import pytest

from frictionlab.cli import main

distributed = pytest.importorskip("distributed")

LAWS = ["wear", "coulomb"]
DATA = ["incline-oil-a100", "impact-golf-v28", "spring-slider-slip"]  # the last: nothing to fit (no law applies)
OPTIONS = dict(laws=LAWS, datasets=DATA, bootstrap=12, tolerance=(1e-3,), replicates=20, seed=3)


def numbers(c):
    """Everything results.json records but the clocks (times, dates) and where it ran."""
    import json
    import re

    from frictionlab.report import results_json

    def strip(x):
        if isinstance(x, str):  # a sentence quoting a measured time ("its fit took 1.4 CPU s")
            return re.sub(r"\d+(\.\d+)? (CPU )?s\b", "# s", x)
        if isinstance(x, dict):
            return {k: strip(v) for k, v in x.items()
                    if not any(w in k for w in ("time", "timings", "cpu", "wall", "created", "settings", "versions"))}
        if isinstance(x, list):
            return [strip(v) for v in x]
        return x

    return strip(json.loads(json.dumps(results_json(c, {}))))


@pytest.fixture(scope="module")
def local():
    from frictionlab.pipeline.comparison import compare

    return compare(jobs=1, **OPTIONS)


@pytest.mark.parametrize("workers", [1, 2])
def test_cluster_gives_the_local_numbers(local, workers, tmp_path):
    from frictionlab.pipeline.comparison import compare
    from frictionlab.report import DRAW_BATCH, build, write_report

    with distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        c = compare(client=client, **OPTIONS)
        assert f"({workers} worker" in c.settings["cluster"]
        assert numbers(c) == numbers(local)
        if workers == 2:  # the figures drawn on the workers (several a task) are the local ones, byte for byte
            out = write_report(c, tmp_path / "r", client=client)
            figs = [f for s in build(c)[0] for f in s.figures]
            assert len(figs) > 2 * DRAW_BATCH
            for f in figs:
                assert (out / "figures" / f.name).read_bytes() == f.draw()


def test_bad_scheduler_is_one_line(tmp_path, capsys):
    assert main(["compare", "--scheduler", "nonsense://nowhere", "--out", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--scheduler nonsense://nowhere" in err[0]
    assert not (tmp_path / "r").exists()


def test_workers_are_prepared_once_per_warm_function():
    """``core.cluster.prepare`` runs its warm-up (imports, malloc thresholds) once per worker and function."""
    from frictionlab.core import cluster

    def warm():  # counts its runs in the worker process's environment
        import os

        os.environ["FRICTIONLAB_TEST_WARM"] = str(int(os.environ.get("FRICTIONLAB_TEST_WARM", "0")) + 1)

    def runs():
        import os

        return os.environ.get("FRICTIONLAB_TEST_WARM")

    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as lc, distributed.Client(lc) as client:
        key = warm.__qualname__ + "@" + warm.__module__
        assert set(client.run(cluster._prepared, key).values()) == {False}
        cluster.prepare(client, warm)
        cluster.prepare(client, warm)  # the second call finds every worker prepared
        assert set(client.run(cluster._prepared, key).values()) == {True}
        assert set(client.run(runs).values()) == {"1"}


def _watching(dask_worker) -> dict:
    """Of each of the worker's callbacks that ``core.cluster.quietly`` quietens: its period in ms, None if stopped."""
    from frictionlab.core.cluster import QUIET

    pcs = {name: dask_worker.periodic_callbacks[name] for name in QUIET}
    return {name: pc.callback_time if pc.is_running() else None for name, pc in pcs.items()}


def _quiet_within(seconds: float) -> dict:
    """In a task: the worker's watching callbacks once quietened (within ``seconds``: it is queued on its loop)."""
    import time

    from distributed import get_worker

    worker, end = get_worker(), time.monotonic() + seconds
    while time.monotonic() < end and _watching(worker)["profile"] is not None:
        time.sleep(0.01)
    return _watching(worker)


def test_worker_quietened_only_while_frictionlab_tasks_run():
    """``core.cluster.executor``'s tasks stop the worker's profiler and slow its tick and system monitor; all
    run as before afterwards, and a task submitted on the client directly (not frictionlab's) changes nothing."""
    import time

    from frictionlab.core.cluster import QUIET, executor

    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as lc, distributed.Client(lc) as client:
        (before,) = client.run(_watching).values()
        assert None not in before.values() and before["tick"] < QUIET["tick"]
        assert client.submit(_quiet_within, 0.5, pure=False).result() == before
        with executor(1, client) as ex:
            futures = [ex.submit(_quiet_within, 5.0) for _ in range(3)]
            assert [f.result() for f in futures] == [QUIET] * 3
        end = time.monotonic() + 5
        while time.monotonic() < end and list(client.run(_watching).values()) != [before]:
            time.sleep(0.05)
        assert list(client.run(_watching).values()) == [before]
