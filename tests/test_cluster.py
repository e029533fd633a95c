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
        if isinstance(x, str):  # a sentence quoting a measured time ("its fit took 1.4 CPU s", "at 4.8× its time")
            return re.sub(r"[\d.]+(–[\d.]+)?×", "#×", re.sub(r"\d+(\.\d+)? (CPU )?s\b", "# s", x))
        if isinstance(x, dict):
            return {k: strip(v) for k, v in x.items()
                    if not any(w in k for w in ("time", "timings", "cpu", "wall", "created", "settings", "versions"))}
        if isinstance(x, list):
            return [strip(v) for v in x]
        return x

    return strip(json.loads(json.dumps(results_json(c, {}))))


def _differences(a, b, path="") -> list[str]:
    """Where two JSON-like values differ: paths with both values, for the failure message."""
    if isinstance(a, dict) and isinstance(b, dict):
        return [d for k in a.keys() | b.keys() for d in _differences(a.get(k), b.get(k), f"{path}/{k}")]
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        return [d for i, (x, y) in enumerate(zip(a, b)) for d in _differences(x, y, f"{path}[{i}]")]
    return [] if a == b else [f"{path}: {a!r:.80} != {b!r:.80}"]


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
        got, want = numbers(c), numbers(local)
        assert got == want, f"differs at {_differences(got, want)[:5]}"
        if workers == 2:  # the figures drawn on the workers (several a task) are the local ones, byte for byte
            out = write_report(c, tmp_path / "r", client=client)
            figs = [f for s in build(c)[0] for f in s.figures]
            assert len(figs) >= 2 * DRAW_BATCH  # two tasks of several figures at least
            for f in figs:
                assert (out / "figures" / f.name).read_bytes() == f.draw()


def test_bad_scheduler_is_one_line(tmp_path, capsys):
    assert main(["compare", "--scheduler", "nonsense://nowhere", "--out", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--scheduler nonsense://nowhere" in err[0]
    assert not (tmp_path / "r").exists()


def test_workers_are_prepared_once_per_warm_function():
    """``core.cluster.prepare`` runs its warm-up once per worker and function, in a child process per worker
    thread, where the tasks run, and not in the worker process, which passes tasks and replies on unread."""
    import os

    from frictionlab.core import cluster

    def warm():  # appends this process's id to a list in its environment
        import os

        os.environ["FRICTIONLAB_TEST_WARM"] = os.environ.get("FRICTIONLAB_TEST_WARM", "") + f"{os.getpid()},"

    def runs():
        import os

        return os.environ.get("FRICTIONLAB_TEST_WARM"), os.getpid()

    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as lc, distributed.Client(lc) as client:
        key = warm.__qualname__ + "@" + warm.__module__
        assert set(client.run(cluster._prepared, key).values()) == {False}
        cluster.prepare(client, warm)
        cluster.prepare(client, warm)  # the second call finds every worker prepared
        assert set(client.run(cluster._prepared, key).values()) == {True}
        workers = set(client.run(os.getpid).values())
        assert all(ran is None for ran, pid in client.run(runs).values())
        worker_modules = client.run(lambda: sorted(m for m in __import__("sys").modules if m.startswith("frictionlab")))
        with cluster.executor(1, client, warm=warm) as ex:
            done = {f.result() for f in [ex.submit(runs) for _ in range(6)]}
        assert len(done) <= 2  # at most one child per worker (one thread each), reused
        for ran, pid in done:  # in a child: its own warm-up, once
            assert ran == f"{pid}," and pid not in workers
        for modules in worker_modules.values():  # the worker imports no more of frictionlab than passing tasks on
            assert set(modules) <= {"frictionlab", "frictionlab.core", "frictionlab.core.errors",
                                    "frictionlab.core.taskhost", "frictionlab.core.cluster", "frictionlab.core.address",
                                    "frictionlab.core.workers"}, modules


def _child(kind: str):
    """A task for ``test_tasks_run_in_a_child_of_the_worker``."""
    import os
    import sys

    if kind == "where":
        print("a task's own output on stdout")  # not on the pipe the reply takes
        return os.getpid(), os.getppid(), "MALLOC_TRIM_THRESHOLD_" in os.environ, list(sys.path)
    if kind == "raise":
        raise KeyError("the task's own error")
    os.kill(os.getpid(), 9)


def test_tasks_run_in_a_child_of_the_worker(tmp_path):
    """On a worker, ``core.cluster.executor``'s tasks run in a child process of it (``core.taskhost``), reused
    from task to task, with the worker's sys.path and not the nanny's malloc setting; the task's exception
    comes back as itself; a child that dies is a one-line WorkerLost, and the next task gets a new child."""
    import os

    from frictionlab.core.cluster import executor
    from frictionlab.core.errors import WorkerLost

    def add_path(path):
        import sys

        sys.path.append(path)

    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as lc, distributed.Client(lc) as client:
        (worker,) = client.run(os.getpid).values()
        client.run(add_path, str(tmp_path))  # as client.upload_file does: the child starts with the worker's path
        with executor(1, client) as ex:
            first, again = ex.submit(_child, "where").result(), ex.submit(_child, "where").result()
            assert first[1] == worker and first[0] != worker and again[0] == first[0]
            assert first[2] is False and str(tmp_path) in first[3]
            with pytest.raises(KeyError, match="the task's own error"):
                ex.submit(_child, "raise").result()
            with pytest.raises(WorkerLost, match="child process of the Dask worker died") as lost:
                ex.submit(_child, "die").result()
            assert "\n" not in str(lost.value)
            after = ex.submit(_child, "where").result()
            assert after[1] == worker and after[0] != first[0]


SCRIPT_LAW = '''
import logging
import numpy as np
import distributed
import frictionlab as fl
from frictionlab import FrictionLaw, ParamSpec, register_law


@register_law
class MainDry(FrictionLaw):
    """Dry friction, registered in the script that runs compare (its __main__)."""

    name = "main-dry"
    formula = "F = mu_k N sign(u)"
    citation = "test"
    params = (ParamSpec("mu_k", "", 0.2, 0.0, 5.0, 0.3, "kinetic"),)
    requires = frozenset({"u", "N"})

    def force(self, p, c):
        return p["mu_k"] * c.N * np.sign(c.u)


if __name__ == "__main__":
    logging.getLogger("distributed").setLevel(logging.ERROR)
    opts = dict(laws=["main-dry"], datasets=["incline-dry-d10"], bootstrap=0, tolerance=(), equivalence=False)
    here = fl.compare(jobs=1, **opts)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as lc, \\
            distributed.Client(lc) as client:
        there = fl.compare(client=client, **opts)
    print([(f.status, f.reason) for f in there.fits])
    assert [f.status for f in there.fits] == ["ok"], [f.reason for f in there.fits]
    assert [f.params["mu_k"].value for f in there.fits] == [f.params["mu_k"].value for f in here.fits]
    print("SAME")
'''


def test_a_law_registered_in_the_main_script_fits_on_the_cluster(tmp_path):
    """A law registered at import in the script that calls compare is known where the tasks run, as it is in the
    worker (multiprocessing imports the script there as __mp_main__): the child process starts the same way."""
    import subprocess
    import sys

    script = tmp_path / "with_my_law.py"
    script.write_text(SCRIPT_LAW)
    run = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert run.returncode == 0 and "SAME" in run.stdout, run.stdout[-2000:] + run.stderr[-2000:]
