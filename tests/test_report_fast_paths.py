"""What the report's figures compute once and share, against computing it each time: a best-fit trajectory drawn
by several figures (figures.base.trajectory) and the Hertz pulse at one time (an ODE's right-hand side) against
the same pulse at an array of times; figures drawn on the kept canvases against fresh ones."""
import numpy as np
import pytest
from _fit_helpers import TRUTH, synthetic

from frictionlab import fit
from frictionlab.core.errors import FrictionLabError
from frictionlab.report.figures import base
from frictionlab.solve.outcomescene import HertzPulse, hertz_shape


@pytest.fixture(scope="module")
def wear_fit():
    return fit("wear", synthetic("wear", TRUTH["wear"], seed=5, rel_noise=0.01, name="c"))


def test_a_trajectory_is_simulated_once_per_report_and_is_the_fits_own(wear_fit, monkeypatch):
    d = wear_fit.per_dataset[0]
    t = np.linspace(0.0, float(d.target.t[-1]), 300)
    calls = []
    own = type(d).trajectory
    monkeypatch.setattr(type(d), "trajectory", lambda self, law, tt: (calls.append(len(tt)), own(self, law, tt))[1])
    base.release()
    first = base.trajectory(d, "wear", t)
    again = base.trajectory(d, "wear", t.copy())  # the same times: the same curve, not simulated again
    other = base.trajectory(d, "wear", t[:200])
    assert calls == [300, 200] and again is first and len(other.t) == 200
    plain = own(d, "wear", t)
    assert np.array_equal(first.t, plain.t) and np.array_equal(first.force, plain.force)
    assert np.array_equal(first["omega"], plain["omega"])
    base.release()  # a report's end: computed anew
    assert base.trajectory(d, "wear", t) is not first and calls == [300, 200, 300]
    base.release()


def test_a_trajectory_the_solver_refuses_is_refused_each_time(wear_fit, monkeypatch):
    d = wear_fit.per_dataset[0]

    def refuse(self, law, t):
        raise FrictionLabError("over the budget")

    monkeypatch.setattr(type(d), "trajectory", refuse)
    base.release()
    for _ in range(2):
        with pytest.raises(FrictionLabError, match="over the budget"):
            base.trajectory(d, "wear", np.linspace(0.0, 1e-3, 5))
    base.release()


def test_the_memo_lets_go_beyond_its_size(wear_fit):
    d = wear_fit.per_dataset[0]
    base.release()
    for k in range(base.MEMO + 3):
        base.trajectory(d, "wear", np.linspace(0.0, 1e-4, 3 + k))
    assert len(base._KEPT.trajectories) <= base.MEMO
    base.release()


def test_the_hertz_pulse_at_one_time_is_the_pulse_at_an_array_of_times():
    pulse = HertzPulse(stiffness=2.3e9, delta_max=4e-5, normal_speed=1.7)
    s_end = hertz_shape()[0]
    ts = pulse.time_scale * np.concatenate([np.random.default_rng(0).uniform(-0.1, 1.1 * s_end, 4000),
                                            [0.0, s_end, -0.0, np.nextafter(s_end, 9.0), 1e-300, np.nan, np.inf]])
    many = pulse.shape(ts)
    for k, t in enumerate(ts):
        one = pulse.shape(t)
        assert all(isinstance(v, (np.ndarray, np.floating)) and np.shape(v) == () for v in one)
        assert (one[0], one[1]) == (many[0][k], many[1][k]) or (np.isnan(t) and one == (0.0, 0.0)), t
    inside = (ts >= 0) & (ts <= s_end * pulse.time_scale)
    assert inside.sum() > 3000 and np.all(many[0][~inside] == 0.0)


@pytest.fixture(scope="module")
def small_comparisons():
    from frictionlab import compare
    from frictionlab.io.dataset import load_dataset

    series = [synthetic("area-rate", TRUTH["area-rate"], seed=3, name="a"),
              synthetic("wear", TRUTH["wear"], seed=5, rel_noise=0.002, name="c-" + "long-name-" * 4)]
    return (compare(laws=["coulomb", "wear", "area-rate"], datasets=series),
            compare(laws=["coulomb", "wear"], datasets=[load_dataset("impact-outcome-synthetic")]))


def test_figures_drawn_on_kept_canvases_are_the_figures_drawn_on_fresh_ones(small_comparisons, monkeypatch):
    """Every figure of two reports (fits, force, ranking, discrimination, equivalence, first screen, outcomes)
    with spin in a unit 1e5 times rpm (offset texts above the axes) drawn one after another on the kept canvases
    (``base.subplots``: each emptied and drawn on again), and each on a fresh canvas: the same PNG bytes, each a
    PNG Pillow reads at the figure's size. In the display units: tests/test_figure_reuse.py."""
    scale = 1e5
    import io

    from PIL import Image

    from frictionlab import report
    from frictionlab.core import display

    name, factor = display.OBSERVABLE_UNITS["omega"]
    monkeypatch.setitem(display.OBSERVABLE_UNITS, "omega", (name, factor * scale))
    figures = [f for c in small_comparisons for page in report._pages(c, {}) for sec in page[1] for f in sec.figures]
    assert {"fit", "force", "ranking", "discrimination", "finding"} <= {f.name.split("-")[0].split(".")[0]
                                                                       for f in figures}
    base.release()
    kept = [f.draw() for f in figures]
    fresh = []
    for f in figures:
        base.release()
        fresh.append(f.draw())
    base.release()
    assert [f.name for f, a, b in zip(figures, kept, fresh) if a != b] == []
    for data in kept:
        image = Image.open(io.BytesIO(data))
        image.load()
        assert image.format == "PNG" and min(image.size) > 50
