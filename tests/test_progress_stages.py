"""Progress where a person waits: a fit names its stages with a count; compare names each stage as it
begins; a quick run behind a delay stays silent, a slow one does not."""
import io
import time

from _fit_helpers import synthetic

from frictionlab import compare, fit
from frictionlab.core.progress import Progress


def test_a_fit_names_its_stages_and_counts_evaluations():
    calls = []
    ds = synthetic("wear", {"lam": 1.81e6}, seed=3, n=21, name="impact-p")
    r = fit("wear", ds, progress=lambda d, t, label: calls.append((d, t, label)))
    assert r.ok
    labels = [c[2] for c in calls]
    order = ["scanning start points", "Levenberg-Marquardt start 1 of", "error analysis", "ok after"]
    at = [next(i for i, x in enumerate(labels) if s in x) for s in order]
    assert at == sorted(at) and all(x.startswith("wear on impact-p: ") for x in labels)
    assert all(0 <= d <= t for d, t, _ in calls) and calls[-1][0] == calls[-1][1]
    assert [d for d, _, _ in calls] == sorted(d for d, _, _ in calls)  # the count never goes back
    scan = [x for x in labels if "scanning" in x]
    assert scan[-1].endswith(f"{int(scan[-1].split(', ')[-1].split()[0])} evaluations")


def test_compare_names_each_stage_as_it_begins():
    labels = []
    ds = synthetic("wear", {"lam": 1.81e6}, seed=4, n=21, name="impact-q")
    compare(laws=["wear", "coulomb"], datasets=[ds], progress=lambda d, t, label: labels.append(label))
    started = [x for x in labels if x.startswith("stage ")]
    assert started[:2] == ["stage fit started", "stage rank started"] and "stage answer started" in started


def test_a_delayed_progress_is_silent_for_a_quick_run_and_speaks_after_the_delay():
    quiet, slow = io.StringIO(), io.StringIO()
    with Progress("x", stream=quiet, tty=False, delay=5.0) as bar:
        bar(1, 2, "a")
        bar(2, 2, "b")
    assert quiet.getvalue() == ""
    with Progress("x", stream=slow, tty=False, delay=0.2, heartbeat=0) as bar:
        bar(1, 3, "a")
        time.sleep(0.3)
        bar(2, 3, "b")
        bar(3, 3, "c")
    lines = slow.getvalue().splitlines()
    assert "x: 1/3" not in slow.getvalue() and lines[-1].split(" x: ")[1].startswith("3/3 (100%) c; took")
