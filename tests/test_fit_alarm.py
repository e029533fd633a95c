"""The fit's time budget alarm never lands inside an import or numba: a module imported when the budget runs out is
imported whole (and numba set up whole) before the fit stops; anywhere else the alarm stops the fit."""
from __future__ import annotations

import sys
import time

import pytest

from frictionlab.inference.fitting.alarm import ALARM_RETRY, FitTimeout, alarm


def _busy(seconds: float) -> None:
    end = time.perf_counter() + seconds
    while time.perf_counter() < end:
        pass


def test_a_module_imported_when_the_budget_runs_out_is_imported_whole(tmp_path, monkeypatch):
    (tmp_path / "slow_import_probe.py").write_text(
        "import time\nend = time.perf_counter() + 0.3\nwhile time.perf_counter() < end:\n    pass\ndone = True\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, "slow_import_probe", raising=False)
    with pytest.raises(FitTimeout):  # after the import: the busy loop's five seconds never end on their own
        with alarm(0.05):
            import slow_import_probe  # noqa: F401  (the alarm rings in the middle of this)
            _busy(5.0)
    assert sys.modules["slow_import_probe"].done is True


def test_outside_an_import_the_alarm_stops_the_fit():
    with pytest.raises(FitTimeout):
        with alarm(ALARM_RETRY):
            _busy(5.0)
