"""The bad-input corpus of a run's surroundings, tests/bad_inputs/runs.toml: a cluster that fails, outputs that
are a set (a full disk, a run killed with SIGKILL), exit statuses and the messages of numerical failures, and a
run kept independent of what plugins and callers do to the process.

Every case, whatever its class, is checked as the other corpora are (``test_bad_inputs_by_class.check``): its exit
status, no traceback, nothing a terminal acts on, and with status 2 exactly one error line matching ``error``
and the case folder as it was. The fields beyond by_class.toml's are described at the top of runs.toml.
"""
from __future__ import annotations

import contextlib
import fcntl
import os
import re
import signal
import subprocess
import sys
import textwrap
import time
import tomllib
from pathlib import Path

import pytest

from test_bad_inputs import clean_registry, prepare, snapshot  # noqa: F401 (a fixture)
from test_bad_inputs_by_class import check, run_inprocess, run_python

CASES = tomllib.loads((Path(__file__).parent / "bad_inputs" / "runs.toml").read_text(encoding="utf-8"))["case"]
CLASSES = ("cluster", "outputs", "statuses", "process")
FIELDS = {"id", "class", "sees", "base", "edit", "files", "argv", "python", "raises", "status", "error", "stdout",
          "stderr", "never", "written", "absent", "env", "how", "slow", "cluster", "kill", "disk", "dist", "within",
          "kill9", "then", "left", "hold_lock", "ps_never"}

#: Law plugins installed as distributions (entry points) for a case (``dist``), so that Dask's workers find them.
DISTS = {
    "sleepy": ('''
        import time
        import numpy as np
        from frictionlab import FrictionLaw, ParamSpec


        class Sleepy(FrictionLaw):
            """Coulomb friction that takes half a second a call once a fit runs."""
            name = "sleepy"
            formula = "F = mu N sign(u)"
            citation = "a test"
            params = (ParamSpec("mu", "", 0.3, 0.0, 5.0, 0.3, "coefficient"),)
            requires = frozenset({"u", "N"})

            def force(self, p, c):
                if np.size(c.u) > 5:  # not the registration probe
                    time.sleep(0.5)
                return p["mu"] * c.N * np.sign(c.u)
        ''', "sleepy = sleepy_law:Sleepy"),
}


def params():
    return [pytest.param(c, id=c["id"], marks=[pytest.mark.slow] if c.get("slow") else []) for c in CASES]


def write_dist(root: Path, name: str) -> None:
    code, entry = DISTS[name]
    (root / f"{name}_law.py").write_text(textwrap.dedent(code))
    info = root / f"{name}_dist-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}-dist\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(f"[frictionlab.laws]\n{entry}\n")


@contextlib.contextmanager
def tmpfs(folder: Path, size: str, fill: int):
    """A tmpfs of ``size`` mounted on ``folder``, ``fill`` bytes of it taken by the file 'fill'; skip where the
    test cannot mount one (not root, no mount namespace)."""
    folder.mkdir()
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(folder)], capture_output=True)
    if done.returncode != 0:
        folder.rmdir()
        pytest.skip(f"cannot mount a tmpfs to fill the disk (needs root): {done.stderr.decode().strip()}")
    try:
        with open(folder / "fill", "wb") as f:
            f.write(b"\0" * fill)
        yield
    finally:
        subprocess.run(["umount", "-l", str(folder)], capture_output=True)


@contextlib.contextmanager
def cluster(kind: str, folder: Path, env: dict):
    """What ``{scheduler}`` names: a silent server, an HTTP server, a port nobody listens on, or a Dask cluster with
    0 or 1 workers (``Processes``, killable). Yields (address, processes or None)."""
    from _dask_procs import Http, Processes, Silent, free_port

    if kind == "silent":
        server = Silent()
    elif kind == "http":
        server = Http()
    elif kind == "refused":
        yield f"tcp://127.0.0.1:{free_port()}", None
        return
    else:
        pytest.importorskip("distributed")
        procs = Processes(str(folder), env={**os.environ, **env})
        try:
            address = procs.scheduler()
            if kind == "one-worker":
                procs.worker()
            yield address, procs
        finally:
            procs.stop()
        return
    try:
        yield server.address, None
    finally:
        server.stop()


def run_cli(case, argv, tmp: Path, env: dict, procs=None):
    """The command in a subprocess (``python -m frictionlab``: the console script's way to end), with ``kill`` /
    ``kill9`` applied when a stderr line matches; (status, stdout, stderr, seconds)."""
    full_env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(Path(__file__).parent), env.get("PYTHONPATH", "")]),
                **{k: v for k, v in env.items() if k != "PYTHONPATH"}}
    started = time.monotonic()
    proc = subprocess.Popen([sys.executable, "-m", "frictionlab", *argv], cwd=tmp, env=full_env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, errors="backslashreplace")
    lines, act = [], case.get("kill") or case.get("kill9")
    if act:
        for line in proc.stderr:
            lines.append(line)
            if re.search(act["when"], line):
                if case.get("kill9"):
                    proc.send_signal(signal.SIGKILL)
                else:
                    kill_in(procs, act["what"])
                break
    try:
        out, err = proc.communicate(timeout=case.get("within", 300) + 60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    return proc.returncode, out, "".join(lines) + err, time.monotonic() - started


def kill_in(procs, what: str) -> None:
    """SIGKILL the cluster's scheduler, or every worker."""
    if what == "scheduler":
        procs.kill(procs.sched)
    else:
        for p in procs.procs:
            if p is not procs.sched:
                procs.kill(p)


@contextlib.contextmanager
def lock_held(path: Path):
    """Another process holding an flock on ``path`` (as a process a dead run forked would) until the block ends."""
    holder = subprocess.Popen([sys.executable, "-c", textwrap.dedent(f"""
        import fcntl, os, sys, time
        fd = os.open({str(path)!r}, os.O_RDWR)
        fcntl.flock(fd, fcntl.LOCK_EX)
        print('held', flush=True)
        time.sleep(600)
        """)], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        yield holder.pid
    finally:
        holder.kill()
        holder.wait()


def me() -> str:
    """'PID-START' of this test process (a live owner)."""
    from frictionlab.core.files import owner

    return owner()


def velstep_record() -> str:
    """A raw velocity-step record (the steadystate format): 1 -> 10 um/s at 10 s, sampled at 100 Hz, friction
    following the step as rate-and-state friction does, with a little noise."""
    import numpy as np

    t = np.arange(0.0, 20.0, 0.01)
    after = np.clip(t - 10.0, 0.0, None)
    x = np.where(t < 10.0, 1.0 * t, 10.0 + 10.0 * after)
    mu = 0.6 + np.where(t < 10.0, 0.0, 0.01 * np.log(10.0) * np.exp(-10.0 * after / 20.0) - 0.004 * np.log(10.0)
                        * (1 - np.exp(-10.0 * after / 20.0)))
    mu += 2e-5 * np.random.default_rng(7).standard_normal(t.size)
    rows = "\n".join(f"{a:.3f} {b:.5f} {c:.6f} 10.000" for a, b, c in zip(t, x, mu))
    return "Time(s) Displ(microns) Friction EffectiveNormalstress(MPa)\n" + rows + "\n"


def filled(case: dict) -> dict:
    """A copy of ``case`` with {me} and {pid} filled in (in argv, env, file paths and contents, written, absent)
    and generated files made."""
    import copy

    case = copy.deepcopy(case)
    subst = {"{me}": me(), "{pid}": str(os.getpid())}

    def fill(text: str) -> str:
        for k, v in subst.items():
            text = text.replace(k, v)
        return text

    case["argv"] = [fill(a) for a in case.get("argv", [])]
    case["env"] = {k: fill(v) for k, v in case.get("env", {}).items()}
    for key in ("written", "absent"):
        if key in case:
            case[key] = [fill(p) for p in case[key]]
    for f in case.get("files", []):
        f["path"] = fill(f["path"])
        if f.get("make") == "velstep":
            f["content"] = velstep_record()
            del f["make"]
        elif "content" in f:
            f["content"] = fill(f["content"])
    return case


@pytest.mark.parametrize("case", params())
def test_case(case, tmp_path, tmp_path_factory, capsys, monkeypatch, clean_registry):
    assert set(case) <= FIELDS and case["class"] in CLASSES and case["sees"], case["id"]
    case = filled(case)
    with contextlib.ExitStack() as stack:
        env = dict(case["env"])
        outside = tmp_path_factory.mktemp("outside")  # what the case folder must not see: plugins, Dask's files
        if "dist" in case:
            write_dist(outside, case["dist"])
            env["PYTHONPATH"] = str(outside)
        procs, address = None, ""
        if "cluster" in case:
            address, procs = stack.enter_context(cluster(case["cluster"], outside, env))
        if "disk" in case:
            stack.enter_context(tmpfs(tmp_path / "disk", case["disk"]["size"], case["disk"]["fill"]))
        argv = prepare(case, tmp_path, [a.replace("{scheduler}", address) for a in case["argv"]])
        if "hold_lock" in case:
            stack.enter_context(lock_held(tmp_path / case["hold_lock"]))
        before = snapshot(tmp_path)
        monkeypatch.chdir(tmp_path)
        if "python" in case:
            run_python(case, tmp_path)
            return
        if case.get("how") == "inprocess":
            rc, out, err = run_inprocess(argv, capsys)
            took = 0.0
        else:
            rc, out, err, took = run_cli(case, argv, tmp_path, env, procs)
        if "within" in case:
            assert took < case["within"], f"took {took:.1f} s, more than {case['within']} s:\n{err[-2000:]}"
        if "kill9" in case:
            assert rc == -signal.SIGKILL, f"the run was not killed (exit {rc}):\n{err[-2000:]}"
            for rel in case.get("left", []):  # what the killed run left behind, for the rerun to clear
                assert any(tmp_path.glob(rel)), f"the killed run left no {rel}: {sorted(os.listdir(tmp_path))}"
            fill = {"{tmp}": str(tmp_path), "{out}": str(tmp_path / "out"), "{data}": str(tmp_path / "d.toml")}
            rerun = [a.replace("{out}", fill["{out}"]).replace("{tmp}", fill["{tmp}"]).replace("{data}", fill["{data}"])
                     for a in case["then"]]
            rc, out, err, took = run_cli({}, rerun, tmp_path, env)
        check(case, rc, out, err, before, tmp_path)
        for rx in case.get("ps_never", []):  # no process of the run left behind
            ps = subprocess.run(["ps", "-eo", "args"], capture_output=True, text=True).stdout
            assert not re.search(rx, ps.replace(str(tmp_path), "{tmp}")), f"a process matching {rx!r} is left"
        if "disk" in case:
            assert sorted(os.listdir(tmp_path / "disk")) == ["fill"] or case.get("status", 2) == 0, \
                f"the full disk holds {sorted(os.listdir(tmp_path / 'disk'))}"


def test_runs_corpus_counts():
    """At least 40 cases, every class represented, ids unique."""
    ids = [c["id"] for c in CASES]
    assert len(ids) == len(set(ids)) and len(ids) >= 40
    assert {c["class"] for c in CASES} == set(CLASSES)


def test_the_lock_names_its_owner(tmp_path):
    """A lock file holds 'PID-START' of the run holding it (what a later run checks when the flock is held by a
    process the owner forked)."""
    from frictionlab.core.files import output_lock

    with output_lock(tmp_path / "out"):
        assert (tmp_path / ".out.lock").read_text().strip() == me()
    assert not (tmp_path / ".out.lock").exists()


def test_a_flock_held_by_a_live_owner_is_busy(tmp_path):
    """The lock of a run that is alive (its flock held, its owner running) refuses a second run."""
    from frictionlab.core.errors import OutputError
    from frictionlab.core.files import output_lock

    (tmp_path / ".out.lock").write_text(f"{me()}\n")
    with lock_held(tmp_path / ".out.lock"):
        with pytest.raises(OutputError, match="another frictionlab run is writing this output"):
            with output_lock(tmp_path / "out"):
                pass


def test_flock_is_inherited_by_a_fork(tmp_path):
    """Why a lock's owner is written in it: a process forked while the lock is held keeps the flock after the
    owner is gone (the lock file's flock alone would then refuse every later run)."""
    fd = os.open(tmp_path / "l", os.O_RDWR | os.O_CREAT)
    fcntl.flock(fd, fcntl.LOCK_EX)
    pid = os.fork()
    if pid == 0:
        time.sleep(3)
        os._exit(0)
    try:
        os.close(fd)  # the owner lets go...
        other = os.open(tmp_path / "l", os.O_RDWR)
        with pytest.raises(BlockingIOError):  # ...and the child still holds it
            fcntl.flock(other, fcntl.LOCK_EX | fcntl.LOCK_NB)
        os.close(other)
    finally:
        os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
