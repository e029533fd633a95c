"""Hardening: plugins isolated, fits with a time budget, degenerate data skipped, outputs
locked and written with the umask, every write error naming its path, worker pools that die with
the run. The bad-input corpus (tests/bad_inputs/cases.toml) covers the one-line errors; these tests
cover what a corpus case cannot: real signals and concurrent runs in subprocesses, a full disk, the
umask, entry-point plugins.
"""
from __future__ import annotations

import errno
import math
import os
import signal
import subprocess
import sys
import textwrap
import time
import warnings
from pathlib import Path

import pytest

import frictionlab as fl
from frictionlab.core import files as io
from frictionlab.core import outfolder
from frictionlab.core.errors import LawError, OutputError, UnitError
from frictionlab.physics import registry
from frictionlab.physics.law import FrictionLaw, ParamSpec

SLOW_LAW = '''
import time
from frictionlab import FrictionLaw, ParamSpec, register_law

@register_law
class Slow(FrictionLaw):
    name = "slow-viscous"
    formula = "F = c u, slowly"
    citation = "a test of process hygiene"
    params = (ParamSpec("c", "N s/m", 0.01, 0.0, 1.0, 0.01, "viscous coefficient"),)
    requires = frozenset({"u"})

    def force(self, p, c):
        time.sleep(%s)
        return p["c"] * c.u
'''


# --- quantities -------------------------------------------------------------------------------
@pytest.mark.parametrize("text, match", [
    ("9**9**9 g", "a power of a power"),
    ("10**400 g", "exponent 400"),
    ("((9**12)**12)**12 g", "a power of a power"),
    ("1e400 g", "beyond the accepted magnitude"),
    ("1e200*1e200*1e200 kg", "not finite|accepted magnitudes"),
])
def test_hostile_quantities_are_refused_before_pint_evaluates_them(text, match):
    from frictionlab.core.units import to_si

    with pytest.raises(UnitError, match=match) as info:
        to_si(text, "kg", "scene.mass")
    assert str(info.value).startswith("scene.mass: ")


def test_ordinary_quantities_still_convert():
    from frictionlab.core.units import to_si, unit_factor

    assert to_si("46 g", "kg", "m") == pytest.approx(0.046)
    assert to_si("130 mm^2", "m^2", "a") == pytest.approx(1.3e-4)
    assert to_si("1.81e+06 Pa s/m", "Pa*s/m", "lam") == pytest.approx(1.81e6)
    assert to_si("2**3 g", "kg", "m") == pytest.approx(0.008)
    assert to_si("0 m/s", "m/s", "u0") == 0.0
    assert unit_factor("us", "s", "t") == pytest.approx(1e-6)


# --- plugins ----------------------------------------------------------------------------------
def _law(**spec):
    values = {"name": "k", "unit": "N s/m", "default": 1.0, "lower": 0.0, "upper": 10.0, "scale": 1.0,
              "description": "coefficient", **spec}

    class Law(FrictionLaw):
        name = "probe-law"
        formula = "F = k u"
        citation = "a test"
        params = (ParamSpec(**values),)
        requires = frozenset({"u"})

        def force(self, p, c):
            return p["k"] * c.u

    return Law


@pytest.mark.parametrize("spec, match", [
    ({"default": 1.0, "lower": 1.0, "upper": 1.0}, "lower bound 1 must be below upper bound 1"),
    ({"upper": math.inf}, "upper = inf is not a finite real number"),
    ({"lower": -math.inf}, "lower = -inf is not a finite real number"),
    ({"scale": 1e-40}, "scale 1e-40 is out of proportion"),
])
def test_degenerate_parameters_are_refused_at_registration_naming_the_plugin(spec, match):
    with pytest.raises(LawError, match=match) as info:
        fl.register_law(_law(**spec))
    assert "law 'probe-law' (run-time registration of " in str(info.value)
    assert "probe-law" not in fl.available_laws()


def test_a_complex_force_is_refused_naming_the_law_without_a_numpy_warning():
    class Complex(FrictionLaw):
        name = "complex-law"
        formula = "F = k u (1 + i)"
        citation = "a test"
        params = (ParamSpec("k", "N s/m", 1.0, 0.0, 10.0, 1.0, "coefficient"),)
        requires = frozenset({"u"})

        def force(self, p, c):
            return p["k"] * c.u * (1 + 1j)

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numpy's ComplexWarning would fail here
        with pytest.raises(LawError, match=r"law 'complex-law' .*force\(\) returned complex128 values"):
            fl.register_law(Complex)


def _write_dist(root: Path, modules: dict[str, str], entry_points: str) -> None:
    for module, code in modules.items():
        (root / f"{module}.py").write_text(textwrap.dedent(code))
    info = root / "rude_laws-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: rude-laws\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text("[frictionlab.laws]\n" + entry_points)


def test_a_plugin_that_exits_or_interrupts_at_import_is_skipped_not_the_program(tmp_path, monkeypatch, run_cli):
    _write_dist(tmp_path, {"exits": "import sys\nsys.exit(0)\n", "interrupts": "raise KeyboardInterrupt\n"},
                "exits = exits:Law\ninterrupts = interrupts:Law\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            registry.reload_registry()
        messages = sorted(str(w.message) for w in caught if issubclass(w.category, registry.PluginWarning))
        assert len(messages) == 2, messages
        assert "'exits = exits:Law' of rude-laws 0.1: import failed: SystemExit: 0" in messages[0]
        assert "'interrupts = interrupts:Law' of rude-laws 0.1: import failed: KeyboardInterrupt" in messages[1]
        assert "wear" in fl.available_laws()
    finally:
        monkeypatch.undo()
        registry.reload_registry()
    out = run_cli("laws", env={"PYTHONPATH": str(tmp_path)})
    assert out.returncode == 0 and "wear" in out.stdout, out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 2 and all(line.startswith("warning: frictionlab: skipped law plugin") for line in lines)


# --- the time budget of a fit --------------------------------------------------------------------
class _Sluggish(FrictionLaw):
    """Each evaluation sleeps; above k = 2 a single evaluation never returns (a runaway)."""
    name = "sluggish"
    formula = "F = k u"
    citation = "a test of --fit-timeout"
    params = (ParamSpec("k", "N s/m", 1.0, 0.0, 100.0, 1.0, "coefficient"),)
    requires = frozenset({"u"})
    runaway = False

    def force(self, p, c):
        time.sleep(0.01)
        while self.runaway and p["k"] > 2.0:
            pass
        return p["k"] * c.u


@pytest.mark.parametrize("runaway", [False, True], ids=["slow-calls", "one-call-runs-away"])
def test_a_fit_past_its_time_budget_is_a_failed_result_with_the_reason(runaway):
    law = _Sluggish()
    law.runaway = runaway
    result = fl.fit(law, "incline-oil-a100", timeout=0.5)
    assert result.status == "failed"
    assert "exceeded its time budget of 0.5 s (--fit-timeout)" in result.reason
    assert result.wall_time < 30  # it stopped: without the budget the runaway never returns
    assert signal.getitimer(signal.ITIMER_REAL)[0] == 0  # no alarm left armed


def test_compare_turns_a_runaway_fit_into_a_failed_row(monkeypatch):
    fl.register_law(_Sluggish)
    try:
        c = fl.compare(laws=["sluggish", "wear"], datasets=["incline-oil-a100"], equivalence=False,
                       fit_timeout=3.0)  # sluggish sleeps far longer; wear fits within it on a loaded machine
    finally:
        registry.unregister_law("sluggish")
    by_law = {f.law: f for f in c.fits}
    assert by_law["sluggish"].status == "failed" and "time budget" in by_law["sluggish"].reason
    assert by_law["wear"].ok
    assert [r.law for r in c.ranking if r.status != "failed"][:1] == ["wear"]


class _StallsLater(_Sluggish):
    """F = k u, whose evaluations never return once ``stall`` is set (after its first fits), and never sleep."""
    name = "stalls-later"
    citation = "a test of --fit-timeout on refits"
    stall = False

    def force(self, p, c):
        while type(self).stall:
            pass
        return p["k"] * c.u


def test_refits_of_the_equivalence_test_bootstrap_and_transfer_keep_the_time_budget():
    from frictionlab.inference.resampling.ranking_bootstrap import bootstrap_fits
    from frictionlab.inference.equivalence.discrimination import MIN_REPLICATES, analyze_equivalence
    from frictionlab.inference.equivalence.transfer import shared_fit

    fl.register_law(_StallsLater)
    try:
        fits = [fl.fit(law, name) for name in ("incline-oil-a100", "incline-oil-a200") for law in ("stalls-later", "wear")]
        assert all(f.ok for f in fits)
        _StallsLater.stall = True  # every refit of it now runs away unless its budget stops it
        t0 = time.monotonic()
        e = analyze_equivalence(fits[0], fits[1], replicates=MIN_REPLICATES, timeout=0.05)
        boots, skipped = bootstrap_fits(fits[:2], 4, slow=True, timeout=0.05)  # slow: its fit needs the ODE
        shared = shared_fit([fits[0], fits[2]], timeout=0.05)
        assert time.monotonic() - t0 < 60  # without the budget the first refit never returns
    finally:
        _StallsLater.stall = False
        registry.unregister_law("stalls-later")
    # its refit to wear's curve (the centring of T, before any replicate) stops at the budget: the test fails there
    assert e.status == "failed" and "T cannot be centred" in e.reason and e.s_a.size == 0
    assert math.isnan(e.d_ab) and math.isfinite(e.d_ba)  # its refit to wear's curve stalled; wear's to its curve did not
    (b,) = boots
    stalled = b.results["stalls-later [ode]"]
    assert b.n_ranked == 0 and len(stalled.failures) == 4
    assert all("exceeded its time budget of 0.05 s" in why for why in stalled.failures)
    assert shared.status == "failed" and "did not succeed" in shared.reason
    assert signal.getitimer(signal.ITIMER_REAL)[0] == 0  # no alarm left armed


# --- degenerate data ------------------------------------------------------------------------------
def _tiny(tmp_path, rows: str, name="tiny") -> Path:
    base = fl.load_dataset("incline-oil-a100").path
    text = base.read_text().replace('name = "incline-oil-a100"', f'name = "{name}"\ntime_zero = "0 s"')  # t from 0.25
    (tmp_path / "d.toml").write_text(text.replace('incline = "20 deg"', 'incline = "20 deg"\nduration = "0.5 s"'))
    (tmp_path / "d.csv").write_text("t,v\n" + rows)
    return tmp_path / "d.toml"


def test_fewer_points_than_parameters_plus_one_is_skipped_never_ranked(tmp_path):
    data = fl.load_dataset(_tiny(tmp_path, "0.25,0.05\n0.5,0.1\n"))
    ok = fl.fit("coulomb", data)  # 2 points, 1 parameter: a fit
    assert ok.status == "ok"
    short = fl.fit("coulomb", data, free={"u0": (0.0, 1.0)})  # 2 points, 2 parameters: none
    assert short.status == "skipped"
    assert short.reason == "tiny: 2 data points for 2 free parameters: a fit needs at least 3"
    one = fl.load_dataset(_tiny(tmp_path, "0.5,0.1\n", name="one"))
    c = fl.compare(laws=["coulomb", "wear"], datasets=[one, data], equivalence=False)
    assert {(f.datasets[0], f.status) for f in c.fits} == {("one", "skipped"), ("tiny", "ok")}
    assert all(r.dataset != "one" or r.status == "skipped" for r in c.ranking)
    assert not any(r.dataset == "one" and r.status in ("ok", "best", "tied") for r in c.ranking)


# --- output ---------------------------------------------------------------------------------------
def test_full_disk_names_the_path_and_leaves_nothing(tmp_path, monkeypatch):
    def full(self, *a, **k):
        raise OSError(errno.ENOSPC, "No space left on device")

    out = tmp_path / "report"
    monkeypatch.setattr(Path, "write_text", full)
    with pytest.raises(OutputError) as info:
        with outfolder.atomic_dir(out) as tmp:
            (tmp / "report.md").write_text("a report")
    assert str(info.value).startswith(f"{out}: cannot write") and "No space left on device" in str(info.value)
    assert list(tmp_path.iterdir()) == []

    monkeypatch.undo()
    real_fdopen = os.fdopen

    class Full:
        def __init__(self, fh):
            self.fh = fh

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.fh.close()

        def write(self, data):
            raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(os, "fdopen", lambda fd, *a, **k: Full(real_fdopen(fd, *a, **k)))
    target = tmp_path / "series.csv"
    with pytest.raises(OutputError, match=rf"^{target}: cannot write: No space left on device$"):
        io.atomic_write_text(target, "t,v\n")
    assert list(tmp_path.iterdir()) == []


def test_outputs_get_their_permissions_from_the_umask(tmp_path):
    old = os.umask(0o027)
    try:
        with outfolder.atomic_dir(tmp_path / "rep") as tmp:
            (tmp / "figures").mkdir()
            (tmp / "figures" / "a.png").write_bytes(b"png")
        io.atomic_write_text(tmp_path / "one.csv", "t\n")
    finally:
        os.umask(old)
    mode = lambda p: p.stat().st_mode & 0o777  # noqa: E731
    assert mode(tmp_path / "rep") == 0o750 and mode(tmp_path / "rep" / "figures") == 0o750
    assert mode(tmp_path / "rep" / "figures" / "a.png") == 0o640 and mode(tmp_path / "rep" / outfolder.MARKER) == 0o640
    assert mode(tmp_path / "one.csv") == 0o640


def test_the_final_move_checks_the_target_again(tmp_path):
    out = tmp_path / "rep"
    with pytest.raises(OutputError, match="output folder exists"):
        with outfolder.atomic_dir(out) as tmp:
            (tmp / "report.md").write_text("mine")
            out.mkdir()  # someone else (not frictionlab: no lock) made it meanwhile
            (out / "theirs.txt").write_text("theirs")
    assert sorted(p.name for p in out.iterdir()) == ["theirs.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rep"]


def test_force_replaces_a_report_or_an_empty_folder_and_nothing_else(tmp_path):
    out = tmp_path / "rep"
    for _ in range(2):  # the first creates it, the second replaces a report
        with outfolder.atomic_dir(out, force=True) as tmp:
            (tmp / "report.md").write_text("new")
    empty = tmp_path / "empty"
    empty.mkdir()
    with outfolder.atomic_dir(empty, force=True) as tmp:
        (tmp / "report.md").write_text("new")
    victim = tmp_path / "notes.txt"
    victim.write_text("precious")
    with pytest.raises(OutputError, match="this is not a folder"):
        with outfolder.atomic_dir(victim, force=True):
            pass
    assert victim.read_text() == "precious"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["empty", "notes.txt", "rep"]  # no .old, .tmp, .lock


def _hold_lock(path: Path):
    """A subprocess holding frictionlab's lock on ``path`` until its stdin closes."""
    code = ("import sys; from frictionlab.core.files import output_lock\n"
            f"with output_lock({str(path)!r}):\n    print('held', flush=True); sys.stdin.read()\n")
    proc = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "held"
    return proc


def _refused_while_locked(out: Path, argv: list[str], capsys) -> None:
    """``frictionlab ARGV`` while another process holds the lock on ``out``: exit 2, the one-line error."""
    from frictionlab import cli

    holder = _hold_lock(out)
    try:
        rc = cli.main(argv)
    finally:
        holder.stdin.close()
        holder.wait(10)
    err = capsys.readouterr().err
    assert rc == 2, err
    assert err.strip() == (f"frictionlab: error: {out}: another frictionlab run is writing this output "
                           f"(lock {out.parent / f'.{out.name}.lock'}); wait for it to finish or choose another --out")


def test_a_second_run_to_a_locked_output_fails_at_once_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "rep"
    _refused_while_locked(out, ["compare", "--laws", "wear", "--data", "incline-oil-a100", "--bootstrap", "0",
                                "--no-tolerance", "--out", str(out)], capsys)
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # the holder removed its lock; nothing else


def test_two_concurrent_runs_to_one_output_never_both_succeed(tmp_path):
    out = tmp_path / "rep"
    argv = [sys.executable, "-m", "frictionlab", "compare", "--laws", "wear", "--data", "incline-oil-a100",
            "--bootstrap", "0", "--no-tolerance", "--no-equivalence", "--jobs", "1", "--quiet", "--out", str(out)]
    procs = [subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path)
             for _ in range(2)]
    results = [(p.wait(120), p.stderr.read()) for p in procs]
    codes = sorted(rc for rc, _ in results)
    assert codes == [0, 2], results
    loser = next(err for rc, err in results if rc == 2)
    assert "another frictionlab run is writing this output" in loser or "output folder exists" in loser, loser
    assert (out / "report.md").exists() and (out / outfolder.MARKER).exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rep"]


# --- signals: no worker outlives the run ---------------------------------------------------------
def _children(pid: int) -> set[int]:
    """Process ids whose parent is ``pid`` (from /proc; psutil is not a dependency)."""
    out = set()
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                stat = Path(f"/proc/{entry}/stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                out.add(int(entry))
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"  # a zombie has exited; only its exit status is left


def _compare_with_workers(tmp_path):
    """The command line of a compare run with a slow law (three datasets, two workers) and its output folder."""
    (tmp_path / "slow.py").write_text(SLOW_LAW % "0.005")
    out = tmp_path / "rep"
    return [sys.executable, "-m", "frictionlab", "--load", str(tmp_path / "slow.py"), "compare",
            "--laws", "slow-viscous", "--quiet", "--bootstrap", "0", "--no-tolerance", "--no-equivalence",
            "--out", str(out)], out


def _signal_while_fitting(args, sig, cwd) -> tuple[subprocess.Popen, set[int]]:
    """Start ``args`` with two workers, send ``sig`` once both are fitting, and wait until the run and its
    workers are gone (at most 10 s for the workers); returns the finished process and the workers' pids."""
    proc = subprocess.Popen(args + ["--data", "incline-oil-a100,incline-oil-a200,incline-dry-d10", "--jobs", "2"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=cwd)
    try:
        deadline = time.monotonic() + 60
        workers: set[int] = set()
        while len(workers) < 2 and time.monotonic() < deadline and proc.poll() is None:
            workers |= _children(proc.pid)
            time.sleep(0.05)
        assert len(workers) >= 2, f"the run made no workers: {proc.poll()} {proc.stderr.read() if proc.poll() else ''}"
        time.sleep(0.5)  # the workers are fitting now
        proc.send_signal(sig)
        proc.wait(30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    deadline = time.monotonic() + 10
    while any(_alive(p) for p in workers) and time.monotonic() < deadline:
        time.sleep(0.05)
    return proc, workers


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs /proc")
@pytest.mark.parametrize("sig, code, word", [(signal.SIGTERM, 143, "terminated"), (signal.SIGINT, 130, "interrupted")],
                         ids=["SIGTERM", "SIGINT"])
def test_a_signal_during_compare_with_workers_leaves_no_process_and_no_output(sig, code, word, tmp_path):
    args, _ = _compare_with_workers(tmp_path)
    proc, workers = _signal_while_fitting(args, sig, tmp_path)
    stderr = proc.stderr.read()
    assert proc.returncode == code, stderr
    assert stderr.strip().splitlines()[-1] == f"frictionlab: {word}", stderr
    assert "Traceback" not in stderr
    assert not [p for p in workers if _alive(p)], "worker processes outlived the run"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["slow.py"]  # no report, no lock, no temporary folder


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="parent-death signal is Linux only")
def test_workers_do_not_outlive_a_killed_run_and_the_output_can_be_written_again(tmp_path):
    """SIGKILL cannot be caught: the workers must notice their parent's death themselves (they
    share the output lock they inherited, so an orphan would also block the next run)."""
    args, out = _compare_with_workers(tmp_path)
    _, workers = _signal_while_fitting(args, signal.SIGKILL, tmp_path)
    assert not [p for p in workers if _alive(p)], "worker processes outlived a killed run"
    assert not out.exists()  # written whole or not at all
    again = subprocess.run(args + ["--data", "incline-oil-a100", "--jobs", "1"], capture_output=True, text=True,
                           cwd=tmp_path, timeout=120)
    assert again.returncode == 0, again.stderr
    assert (out / "report.md").is_file()


# --- every quantity of a scene at the edges of the accepted range ----------------------------------
@pytest.mark.parametrize("base", ["impact-golf-v28", "incline-dry-d10", "incline-oil-a100", "impact-outcome-synthetic"])
def test_quantities_at_the_limits_give_errors_naming_the_field_never_a_class(base, tmp_path):
    """Every 'key = "number unit"' of a built-in TOML set to the largest, a negative and the smallest
    accepted magnitude: it loads, or the one-line error names the file, not an internal class."""
    import re

    from frictionlab.core.errors import FrictionLabError
    from frictionlab.io.dataset import builtin_dir

    text = (builtin_dir() / f"{base}.toml").read_text()
    (tmp_path / "d.csv").write_bytes((builtin_dir() / f"{base}.csv").read_bytes())
    fields = list(re.finditer(r'^(\w+) = "([-+0-9.e]+) ([^"]+)"$', text, re.M))
    assert len(fields) >= 5
    for m in fields:
        for value in ("1e100", "-1e100", "1.1e-100"):
            (tmp_path / "d.toml").write_text(text[:m.start()] + f'{m.group(1)} = "{value} {m.group(3)}"'
                                             + text[m.end():])
            try:
                fl.load_dataset(tmp_path / "d.toml")
            except FrictionLabError as exc:
                msg = str(exc)
                assert msg.startswith(str(tmp_path / "d.")), msg
                assert not re.search(r"\b[A-Z][a-z]+[A-Z]\w*\.\w+", msg), msg  # like WeightNormal.value


def test_a_full_disk_during_compare_is_one_line_naming_the_report(tmp_path, monkeypatch, capsys):
    from frictionlab import cli

    def full(self, *a, **k):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(Path, "write_bytes", full)
    monkeypatch.setattr(Path, "write_text", full)
    monkeypatch.chdir(tmp_path)
    rc = cli.main(["compare", "--laws", "wear", "--data", "incline-oil-a100", "--bootstrap", "0", "--no-tolerance",
                   "--no-equivalence", "--jobs", "1", "--quiet", "--out", "rep"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1, err
    # --out is made absolute against the folder the run starts in (a plugin's chdir cannot move it)
    assert err[0].startswith(f"frictionlab: error: {tmp_path / 'rep'}: cannot write")
    assert err[0].endswith("No space left on device")
    assert list(tmp_path.iterdir()) == []


def _freeze_count(_):
    import gc

    return gc.get_freeze_count()


def test_the_pool_freezes_what_its_workers_inherit_and_unfreezes_it_after():
    """process_pool freezes the parent's objects for the forked workers (their collector leaves those pages
    alone) and unfreezes them when the pool closes, also after an error: nothing stays immortal."""
    import gc

    from frictionlab.core.workers import process_pool

    assert gc.get_freeze_count() == 0
    with process_pool(2) as pool:
        assert gc.get_freeze_count() > 0
        assert pool.submit(_freeze_count, None).result() > 0  # the worker inherited the frozen objects
    assert gc.get_freeze_count() == 0
    with pytest.raises(ZeroDivisionError):
        with process_pool(2):
            1 / 0
    assert gc.get_freeze_count() == 0


def _gc_threshold(_):
    import gc

    return gc.get_threshold()[0]


def test_a_long_run_tunes_the_collector_and_restores_it_after_also_around_a_pool():
    """long_run_gc (compare's whole run): objects built before are frozen and the youngest generation is
    collected less often, in the workers too; a pool inside leaves the run's freeze alone; after the run
    (also after an error) thresholds and freeze are as before."""
    import gc

    from frictionlab.core.workers import GC_YOUNG, long_run_gc, process_pool

    before = gc.get_threshold()
    assert gc.get_freeze_count() == 0
    with long_run_gc():
        assert gc.get_freeze_count() > 0 and gc.get_threshold() == (GC_YOUNG, *before[1:])
        with process_pool(2) as pool:
            assert pool.submit(_gc_threshold, None).result() == GC_YOUNG
        assert gc.get_freeze_count() > 0  # still the run's
    assert gc.get_freeze_count() == 0 and gc.get_threshold() == before
    with pytest.raises(ZeroDivisionError):
        with long_run_gc():
            1 / 0
    assert gc.get_freeze_count() == 0 and gc.get_threshold() == before


def test_datasets_rebuild_into_a_locked_folder_fails_at_once_and_writes_nothing(tmp_path, capsys):
    from frictionlab import cli

    out = tmp_path / "data"
    out.mkdir()
    _refused_while_locked(out, ["datasets", "rebuild", "--out", str(out)], capsys)  # another process rebuilds into it
    assert list(out.iterdir()) == []
    assert cli.main(["datasets", "rebuild", "--out", str(out)]) == 0  # released: the rebuild goes through
    assert len(list(out.iterdir())) > 10 and not (tmp_path / ".data.lock").exists()


def test_a_pool_stopped_by_an_exception_has_its_manager_thread_finished():
    """After ^C in a run with workers, the pool's manager thread is joined before the exception goes on:
    otherwise the interpreter's exit hook races it and prints "OSError: Bad file descriptor" after the
    run's one-line message (ProcessPoolExecutor.shutdown forgets the thread, so it is taken before)."""
    from frictionlab.core.workers import process_pool

    managers = []
    with pytest.raises(KeyboardInterrupt):
        with process_pool(2) as pool:
            pool.submit(time.sleep, 0.2).result()
            manager = pool._executor_manager_thread
            closing = manager.join_executor_internals
            manager.join_executor_internals = lambda: (time.sleep(0.5), closing())  # a slow close: the race, widened
            managers.append(manager)
            pool.submit(time.sleep, 5)
            raise KeyboardInterrupt
    assert managers[0] is not None and not managers[0].is_alive()
