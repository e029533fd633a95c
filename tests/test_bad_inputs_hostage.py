"""Plugins cannot take the process hostage (the corpus's plugin class): a third-party law whose bare ``except:``
swallows the in-process alarm is stopped from outside its code in every stage that calls it (the fit,
the equivalence test's cross-fits, qualitative simulation and replicates, the transfer predictions and
shared fit, the tolerance refits, the bootstrap replicates), with --jobs 1 and --jobs 2; a --load file
or a law probe that hangs is stopped at the load limit; a plugin that takes SIGTERM/SIGINT/SIGHUP over
gives them back."""
from __future__ import annotations

import signal
import time

import pytest

import frictionlab as fl
from frictionlab.core.errors import LawError, RegistryError
from frictionlab.inference.equivalence.discrimination import MIN_REPLICATES
from frictionlab.pipeline.comparison import run_stages
from frictionlab.physics import registry
from frictionlab.physics.law import FrictionLaw, ParamSpec

ENDED = "its process was ended"


class _Swallower(FrictionLaw):
    """F = k u, whose evaluations, once ``stall`` is set, never return and swallow every exception."""
    name = "swallower"
    formula = "F = k u"
    citation = "a test of the time budget kept from outside a plugin"
    params = (ParamSpec("k", "N s/m", 1.0, 0.0, 100.0, 1.0, "coefficient"),)
    requires = frozenset({"u"})
    stall = False

    def force(self, p, c):
        while type(self).stall:
            try:
                time.sleep(0.01)
            except:  # noqa: E722 (the point: the alarm's FitTimeout is swallowed)
                pass
        return p["k"] * c.u


@pytest.fixture(scope="module")
def fitted():
    """A comparison of the swallower and wear on two datasets of one group, fitted (stages fit, rank)."""
    fl.register_law(_Swallower)
    try:
        yield fl.compare(laws=["swallower", "wear"], datasets=["incline-oil-a100", "incline-oil-a200"],
                         stages=["fit", "rank"], pairs=[("swallower", "wear")], bootstrap_all=True)
    finally:
        _Swallower.stall = False
        registry.unregister_law("swallower")


@pytest.fixture
def stalling(fitted):
    _Swallower.stall = True
    try:
        yield fitted
    finally:
        _Swallower.stall = False


BUDGET = 0.2


@pytest.mark.parametrize("jobs", [1, 2])
@pytest.mark.parametrize("stage", ["fit", "equivalence", "transfer", "tolerance", "bootstrap"])
def test_a_plugin_swallowing_the_alarm_is_stopped_from_outside_in_every_stage(stalling, stage, jobs):
    c = stalling
    assert all(f.ok for f in c.fits if f.law == "swallower")
    t0 = time.monotonic()
    done = run_stages(c, [stage], jobs=jobs, fit_timeout=BUDGET, bootstrap=3, tolerance=(1e-3,),
                         replicates=MIN_REPLICATES, equivalence=True)
    assert time.monotonic() - t0 < 60  # without the outside budget the first call never returns
    if stage == "fit":
        reasons = [f.reason for f in done.fits if f.law == "swallower" and not f.ok]  # the refits (after the fits)
        assert len(reasons) == 2
    elif stage == "equivalence":
        reasons = [e.reason for e in done.equivalence if e.status == "failed"]
    elif stage == "transfer":
        (t,) = [t for t in done.transfer if t.shared]
        reasons = [s.reason for s in t.shared if s.law == "swallower"]
        reasons += [p.reason for p in t.predictions if p.law == "swallower"]
        assert all(s.status == "ok" for s in t.shared if s.law == "wear")  # the built-in law's shared fit is made
    elif stage == "tolerance":
        reasons = [r.get("reason") or r.get("error") or str(r) for r in done.tolerance if r["law"] == "swallower"
                   and r.get("rtol") == 1e-3]
    else:
        assert len(done.bootstrap) == 2
        reasons = [why for b in done.bootstrap for why in b.results["swallower [ode]"].failures]
        assert len(reasons) == 2 * 3
    assert reasons and all(ENDED in why for why in reasons), reasons
    assert signal.getitimer(signal.ITIMER_REAL)[0] == 0  # no alarm left armed


def test_built_in_laws_are_not_forked(monkeypatch, fitted):
    """The trusted path: a comparison of built-in laws never runs a call in a bounded child."""
    from frictionlab.inference.fitting import guard

    calls = []

    def bounded(fn, limit, *args):
        calls.append(fn)
        raise guard.OverBudget("not run")

    monkeypatch.setattr(guard, "bounded", bounded)
    fl.compare(laws=["coulomb", "wear"], datasets=["incline-oil-a100", "incline-oil-a200"], fit_timeout=30,
               bootstrap=3, tolerance=(1e-3,), replicates=MIN_REPLICATES, bootstrap_all=True)
    assert calls == []
    c = fl.compare(laws=["swallower"], datasets=["incline-oil-a100"], fit_timeout=30, equivalence=False,
                   transfer=False)
    assert len(calls) == 1 and c.fits[0].status == "failed"  # the check above can fail: a plugin's fit is bounded


class _HangsWhenChecked(FrictionLaw):
    """A law whose force never returns and swallows every exception (so its check at registration hangs)."""
    name = "hangs-when-checked"
    formula = "F = k u"
    citation = "a test of the load time limit"
    params = (ParamSpec("k", "N s/m", 1.0, 0.0, 100.0, 1.0, "coefficient"),)
    requires = frozenset({"u"})

    def force(self, p, c):
        while True:
            try:
                time.sleep(0.01)
            except:  # noqa: E722
                pass


def test_a_law_whose_check_hangs_is_refused_at_the_load_limit(monkeypatch):
    monkeypatch.setenv("FRICTIONLAB_LOAD_TIMEOUT", "0.5")
    t0 = time.monotonic()
    with pytest.raises(LawError, match=r"its check at registration ran past the load time limit of 0.5 s"):
        fl.register_law(_HangsWhenChecked)
    assert time.monotonic() - t0 < 30
    assert "hangs-when-checked" not in fl.available_laws()


def test_a_load_file_that_hangs_at_import_leaves_nothing(monkeypatch, tmp_path):
    import sys

    monkeypatch.setenv("FRICTIONLAB_LOAD_TIMEOUT", "0.5")
    (tmp_path / "stuck.py").write_text("import time\nwhile True:\n    try:\n        time.sleep(0.01)\n    except:\n"
                                       "        pass\n")
    before = set(fl.available_laws())
    with pytest.raises(RegistryError, match=r"--load .*stuck\.py: importing it .* ran past the load time limit"):
        registry.load_law_file(tmp_path / "stuck.py")
    assert "frictionlab_user_stuck" not in sys.modules and set(fl.available_laws()) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["stuck.py"]


def test_a_plugin_that_takes_the_signals_over_in_a_call_gives_them_back():
    from frictionlab.inference.fitting.guard import within_budget

    class Deaf(_Swallower):
        name = "deaf-in-calls"

        def force(self, p, c):
            for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
                signal.signal(s, signal.SIG_IGN)
            return p["k"] * c.u

    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    fl.register_law(Deaf)  # its check calls force here: the handlers come back after it
    try:
        assert {s: signal.getsignal(s) for s in before} == before
        r = within_budget(fl.fit, ["deaf-in-calls"], None, "deaf-in-calls", "incline-oil-a100", over=None)
        assert r.ok and {s: signal.getsignal(s) for s in before} == before
    finally:
        registry.unregister_law("deaf-in-calls")


@pytest.mark.parametrize("jobs", [1, 2])
@pytest.mark.parametrize("stage", ["equivalence", "bootstrap"])
def test_a_plugin_that_ends_its_process_in_a_refit_is_one_error_naming_the_stage(fitted, monkeypatch, stage, jobs):
    import os

    from frictionlab.core.errors import WorkerLost

    def quits(self, p, c):
        os._exit(3)

    monkeypatch.setattr(_Swallower, "force", quits)
    with pytest.raises(WorkerLost, match=rf"^compare: a worker process (was lost|died while running .*) .*in the {stage} stage$"):
        run_stages(fitted, [stage], jobs=jobs, fit_timeout=BUDGET, bootstrap=3, replicates=MIN_REPLICATES,
                   equivalence=True)
