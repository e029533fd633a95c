"""What the report's figures compute once and share, against computing it each time: a best-fit trajectory drawn
by several figures (figures.base.trajectory) and the Hertz pulse at one time (an ODE's right-hand side) against
the same pulse at an array of times."""
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
        assert all(isinstance(v, np.ndarray) and v.shape == () for v in one)
        assert (one[0], one[1]) == (many[0][k], many[1][k]) or (np.isnan(t) and one == (0.0, 0.0)), t
    inside = (ts >= 0) & (ts <= s_end * pulse.time_scale)
    assert inside.sum() > 3000 and np.all(many[0][~inside] == 0.0)


@pytest.mark.parametrize("n, nan", [(5000, False), (7, False), (40, True)])
def test_error_bars_from_plain_arrays_are_matplotlibs_error_bars(n, nan):
    """base.errorbar against Axes.errorbar: the same PNG bytes (bars, markers, legend entry, axis limits) and
    the same artists; a NaN takes matplotlib's own way."""
    rng = np.random.default_rng(n)
    x = np.sort(rng.uniform(0.0, 3.0, n))
    y, err = np.sin(x) + rng.normal(0.0, 0.1, n), rng.uniform(0.01, 0.2, n)
    if nan:
        y[3] = np.nan
    pngs, kinds = [], []
    for way in ("matplotlib", "plain"):
        base.release()
        fig, ((ax,),) = base.subplots("errorbar-test", figsize=(7.6, 3.8))
        style = {"fmt": "o", "ms": 3.2, "color": "black", "ecolor": "0.7", "elinewidth": 0.8, "label": "data",
                 "zorder": 1}
        c = ax.errorbar(x, y, yerr=err, **style) if way == "matplotlib" else base.errorbar(ax, x, y, err, **style)
        ax.legend()
        kinds.append([type(a).__name__ for a in ax.get_children()][:4] + [len(c.lines[2][0].get_segments())])
        assert "vlines" not in vars(ax)  # the axes is left as it was
        base.margins(fig, top=0.1, bottom=0.5)
        pngs.append(base._png(fig))
    base.release()
    assert kinds[0] == kinds[1] and kinds[0][-1] == n
    assert pngs[0] == pngs[1]
