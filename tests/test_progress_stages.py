"""Progress where a person waits: a fit names its stages with a count; compare names each stage as it
begins; a quick run behind a delay stays silent, a slow one does not."""
import io
import time

from _fit_helpers import synthetic

from frictionlab import compare, fit
from frictionlab.core.progress import Progress, Running, _clock


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


def test_compare_counts_every_stage_apart_and_names_it():
    calls = []
    ds = synthetic("wear", {"lam": 1.81e6}, seed=4, n=21, name="impact-q")
    compare(laws=["wear", "coulomb"], datasets=[ds], bootstrap=4, tolerance=(1e-3,), transfer=True,
            progress=lambda d, t, label: calls.append((d, t, label)))
    stages = list(dict.fromkeys(label.split(": ")[0] for _, _, label in calls))
    assert stages[:3] == ["fit", "rank", "equivalence"] and stages[-1] == "answer" and "bootstrap" in stages
    for stage in stages:  # each stage its own count, ending complete
        mine = [(d, t) for d, t, label in calls if label.startswith(stage + ": ")]
        assert all(0 <= d <= t for d, t in mine) and mine[-1][0] == mine[-1][1] > 0, (stage, mine)
    fits = [label for _, _, label in calls if label.startswith("fit: ")]
    assert "fit: running wear [exact] on impact-q" in fits and "fit: coulomb [exact] on impact-q" in fits
    assert calls[-1][2] == "answer: 1 verdict row"


class FakeClock:
    def __init__(self):
        self.t = 1000.0

    def __call__(self):
        return self.t


def test_a_long_step_gets_a_still_working_line_naming_it_and_how_long():
    clock, out = FakeClock(), io.StringIO()
    with Progress("fit", stream=out, tty=False, clock=clock, thread=False) as bar:
        bar(0, 3, "running lugre [ode] on incline-oil-a100")
        bar.beat()  # nothing yet: the line above is fresh
        clock.t += 12
        bar.beat()
        clock.t += 2
        bar.beat()  # written 2 s ago: not again
    lines = out.getvalue().splitlines()
    assert len(lines) == 2 and "\r" not in out.getvalue()
    assert lines[1].endswith("fit: 0/3 done, still working (nothing finished for 0:00:12, 0:00:12 so far); "
                             "last: running lugre [ode] on incline-oil-a100")


def test_stages_have_their_own_count_clock_and_eta():
    clock, out = FakeClock(), io.StringIO()
    with Progress("compare", stream=out, tty=False, clock=clock, thread=False, every=0) as root:
        fit = root.stage("fit")
        fit(0, 2, "2 queued")
        clock.t += 100
        fit(2, 2, "b")
        fit.close()
        clock.t += 50
        boot = root.stage("bootstrap")
        boot(0, 8, "started")
        clock.t += 40
        boot(1, 8, "on x: 1/8 resamples")  # the first step's 40 s (start-up) are not the rate
        for k in (2, 3, 4):
            clock.t += 10
            boot(k, 8, f"on x: {k}/8 resamples")  # 10 s for one: 40 s for the other four, whatever the fits took
        clock.t += 60
        root.beat()
    lines = [x.split(" compare: ")[1] for x in out.getvalue().splitlines()]
    assert lines[:7] == ["fit 0/2 (0%) 2 queued; ETA after the first steps", "fit 2/2 (100%) b; took 0:01:40",
                         "bootstrap 0/8 (0%) started; ETA after the first steps",
                         "bootstrap 1/8 (12%) on x: 1/8 resamples; ETA after the first steps",
                         "bootstrap 2/8 (25%) on x: 2/8 resamples; ETA after the first steps",
                         "bootstrap 3/8 (38%) on x: 3/8 resamples; ETA after the first steps",
                         "bootstrap 4/8 (50%) on x: 4/8 resamples; ETA 0:00:40"]
    assert lines[7].startswith("bootstrap 4/8 done, still working (nothing finished for 0:01:00") and len(lines) == 8


def test_running_names_the_tasks_a_pool_runs_now_from_the_parent_alone():
    clock = FakeClock()
    running = Running(5, workers=2, clock=clock)
    names = ["a", "b", "c", "d", "e"].__getitem__
    clock.t += 3
    running.finished(1)  # b ends at 3 s: c starts on its worker
    clock.t += 7
    assert running.now(names) == "a 10 s, c 7 s"
    running.finished(0)
    clock.t += 1
    assert running.now(names, shown=1) == "c 8 s and 1 more"


def test_the_runner_names_running_pool_tasks_while_none_finishes(monkeypatch):
    """A slow task in a worker: the stage's label names it while the others wait (no timing asserted:
    the slow task ends only once the label named it)."""
    import threading
    from concurrent.futures import ThreadPoolExecutor

    from frictionlab.pipeline import runner
    from frictionlab.pipeline.settings import Settings

    monkeypatch.setattr(runner, "TICK", 0.01)
    seen, named = [], threading.Event()

    def told(done, total, label):
        seen.append((done, total, label))
        if label.startswith("fit: running: slow"):
            named.set()

    def work(task):
        if task == "slow":
            assert named.wait(30)
        return task

    run = runner.Run(settings=Settings(laws=("wear",), jobs=2), plan=None, eq_pairs=[], progress=told)
    run.begin("fit")
    with ThreadPoolExecutor(2) as pool:
        run.pool = pool
        assert run.map(work, ["slow", "quick"], lambda t: t) == ["slow", "quick"]
    assert seen[0] == (0, 2, "fit: 2 queued on 2 workers") and seen[-1][:2] == (2, 2)
    assert any(label.startswith("fit: running: slow ") and " s" in label for _, _, label in seen)


def test_a_fit_estimates_later_starts_from_the_ones_done():
    from frictionlab.inference.fitting.progress import FitProgress

    calls = []
    fp = FitProgress(lambda d, t, label: calls.append((d, t, label)), "lugre on x", 10)
    fp.stage("scanning start points", 10, total=10 + 3 * 20 + 4)
    for _ in range(10):
        fp.tick()
    fp.start(0, 3, guess=20, tail=4)
    assert calls[-1][:2] == (10, 10 + 3 * 20 + 4)
    for _ in range(50):  # the first start takes 50 evaluations, not 20
        fp.tick()
    fp.start(1, 3, guess=20, tail=4)
    assert calls[-1] == (60, 60 + 2 * 50 + 4, "lugre on x: Levenberg-Marquardt start 2 of 3, 0 evaluations")


def test_a_long_start_does_not_make_every_later_start_look_long():
    """Later starts are estimated at the median of the starts done: one start of 100 evaluations among starts of 10
    does not promise 40 for each start left (the mean would)."""
    from frictionlab.inference.fitting.progress import FitProgress

    calls = []
    fp = FitProgress(lambda d, t, label: calls.append((d, t, label)), "lugre on x", 1)
    for i, n in enumerate((10, 100, 10)):
        fp.start(i, 5, guess=20, tail=4)
        for _ in range(n):
            fp.tick()
    fp.start(3, 5, guess=20, tail=4)
    assert calls[-1][:2] == (120, 120 + 2 * 10 + 4)


def test_the_eta_is_the_measured_rate_of_the_counts_not_of_the_moves():
    """Moves of many quick counts and moves of one slow count: the rate is their seconds over their counts (0.6 s a
    count here), not the median move's (1 s a count)."""
    clock, out = FakeClock(), io.StringIO()
    with Progress("fit", stream=out, tty=False, clock=clock, thread=False, every=0) as bar:
        done = 0
        bar(done, 100, "x")
        for step, n in [(1.0, 1)] + [(1.0, 1), (1.0, 4), (1.0, 1), (1.0, 4), (1.0, 1)]:
            clock.t += step
            done += n
            bar(done, 100, "x")
        assert abs(bar.eta(done, 100, clock.t) - (100 - done) * 5.0 / 11) < 1e-9


def test_levenberg_marquardt_is_timed_afresh_after_the_scan():
    """A scan at 1 s an evaluation, then Levenberg-Marquardt at 0.1 s: once the fit's first start begins the rate is
    measured on its evaluations alone (the ETA waits for three moves, then says 0.1 s a count left); later starts
    keep it."""
    from frictionlab.inference.fitting.progress import FitProgress

    clock, out = FakeClock(), io.StringIO()
    with Progress("fit", stream=out, tty=False, clock=clock, thread=False, every=0) as bar:
        restarts = []
        bar.restart_rate = lambda: (restarts.append(bar.done), Progress.restart_rate(bar))
        fp = FitProgress(bar, "lugre on x", 1)
        fp.stage("scanning start points", 10, total=10 + 2 * 100 + 4, other_kind=True)
        for k in range(1, 11):
            clock.t += 1.0
            bar(k, 214, "scan")
        assert abs(bar.eta(10, 214, clock.t) - 204 * 1.0) < 1e-9
        fp.done = 10
        fp.start(0, 2, guess=100, tail=4)
        for k in range(11, 15):
            clock.t += 0.1
            bar(k, 214, "lm")
        assert restarts == [0, 10] and abs(bar.eta(14, 214, clock.t) - 200 * 0.1) < 1e-9
        fp.start(1, 2, guess=100, tail=4)
        assert restarts == [0, 10]


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


def test_a_count_that_moved_gets_its_plain_line_with_eta_from_the_heartbeat():
    clock, out = FakeClock(), io.StringIO()
    with Progress("bench", stream=out, tty=False, clock=clock, thread=False) as bar:
        bar(0, 10, "a")
        clock.t += 1
        bar(1, 10, "b")
        clock.t += 1
        bar(3, 10, "d")  # within 'every' of the last line: not written now
        clock.t += 1
        bar(4, 10, "e")
        clock.t += 1
        bar(5, 10, "f")
        clock.t += 2.5
        bar.beat()
    last = out.getvalue().splitlines()[-1]
    assert last.endswith("bench: 5/10 (50%) f; ETA 0:00:04")  # 3 s for the 4 counts after the first move
    assert "still working" not in out.getvalue()


def test_the_eta_leaves_out_a_first_step_that_paid_for_compilation():
    """A fit whose first evaluations compile for 100 s and whose others take 1 s each: no ETA from the first step
    alone; once two steps have followed the slow one, the ETA is the remaining steps at 1 s (within a second),
    not at the mean since the start (11 s); a later step that waits 30 s is outvoted."""
    clock, out = FakeClock(), io.StringIO()
    with Progress("fit", stream=out, tty=False, clock=clock, thread=False, every=0) as bar:
        bar(0, 100, "scan")
        clock.t += 50
        bar(1, 100, "scan")
        assert bar.eta(1, 100, clock.t) is None and out.getvalue().splitlines()[-1].endswith("after the first steps")
        clock.t += 50
        bar(2, 100, "scan")
        for k in range(3, 5):
            clock.t += 1
            bar(k, 100, "scan")
        assert abs(bar.eta(4, 100, clock.t) - 96) <= 1.0
        assert out.getvalue().splitlines()[-1].endswith(f"; ETA {_clock(96)}")
        clock.t += 30
        bar(5, 100, "scan")
        for k in range(6, 12):
            clock.t += 1
            bar(k, 100, "scan")
        assert abs(bar.eta(11, 100, clock.t) - 89) <= 1.0
