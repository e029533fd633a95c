"""A raw experiment as one record: files of one experiment joined by time, and each step's window starting at a
steady state the data show (the records here are made by the test, in the raw format, from the aging law)."""
from __future__ import annotations

import numpy as np
import pytest

import frictionlab as fl
from frictionlab.cli import main
from frictionlab.core.errors import DatasetError
from frictionlab.io.dataset import load_dataset
from frictionlab.io.steadystate import steady_point
from frictionlab.io.velstep import analyse
from frictionlab.io.velstep_join import read_joined
from frictionlab.physics.scene import ConstantNormal, Scene, SpringLoad
from frictionlab.report.velstep import window

TRUTH = {"mu0": 0.55, "a": 0.010, "b": 0.014, "Dc": 50e-6}
K, SIGMA, CUT = 0.01e6, 2e-4, 110.0  # the record starts CUT s into the history: 10 s after a step up
HEADER = "Time(s)\tDispl(microns)\tFriction\tEffectiveNormalstress(MPa)"
TIMES, VS = (0.0, 100.0, 400.0, 3400.0), (2e-7, 2e-6, 2e-7, 2e-6)  # pieces of 600 um: 12 Dc each
DT, END = 0.5, 3700.0


def _history(end=END, dt=DT):
    """(t, x [um], mu without noise, mu measured) of the history 0.2 -> 2 -> 0.2 -> 2 um/s from its start."""
    t = np.arange(0.0, end, dt)
    scene = Scene(kind="spring-slider", mass=1.0, u0=VS[0], duration=end, normal=ConstantNormal(1.0),
                  spring=SpringLoad(K, TIMES, VS))
    mu = fl.simulate("rate-state-aging", scene, TRUTH, t=t).load
    edges = [*TIMES[1:], np.inf]
    x = sum(v * np.clip(t - a, 0.0, b - a) for a, b, v in zip(TIMES, edges, VS)) * 1e6
    rng = np.random.default_rng(11)
    return t, x + rng.normal(0, 0.05, t.size), mu, mu + rng.normal(0.0, SIGMA, t.size)


def _write(path, t, x, mu, lo, hi):
    rows = [HEADER] + [f"{a:.6f}\t{b:.6f}\t{c:.6f}\t30.000000" for a, b, c in zip(t[lo:hi], x[lo:hi], mu[lo:hi])]
    path.write_text("\n".join(rows) + "\n")


@pytest.fixture(scope="module")
def history():
    return _history()


def test_slices_of_one_recording_join_into_the_whole_record(tmp_path, history):
    t, x, _, mu = history
    lo = int(CUT / DT)
    _write(tmp_path / "whole.txt", t, x, mu, lo, t.size)
    _write(tmp_path / "a.txt", t, x, mu, lo, 3000)
    _write(tmp_path / "b.txt", t, x, mu, 2500, 6000)  # overlaps a.txt by 500 samples
    _write(tmp_path / "c.txt", t, x, mu, 5900, t.size)
    whole = read_joined([tmp_path / "whole.txt"])
    joined = read_joined([tmp_path / "c.txt", tmp_path / "a.txt", tmp_path / "b.txt"])  # any order
    assert np.array_equal(joined.t, whole.t) and np.array_equal(joined.mu, whole.mu)
    assert joined.path.name == "a.txt+b.txt+c.txt"
    i = int(np.searchsorted(joined.t, t[4000]))
    assert joined.where(i) == f"b.txt line {4000 - 2500 + 2}"  # each sample keeps its own file's line
    _write(tmp_path / "d.txt", t, x, mu + 1e-3, 2900, 4000)  # overlaps a.txt with other friction
    with pytest.raises(DatasetError, match=r"d.txt: line 2: t = .* lies within a.txt .* not the same sample"):
        read_joined([tmp_path / "a.txt", tmp_path / "d.txt"])


def test_each_step_window_starts_at_a_steady_state_not_in_the_transient_before(tmp_path, history):
    t, x, clean, mu = history
    lo = int(CUT / DT)
    _write(tmp_path / "r.txt", t, x, mu, lo, t.size)
    imp = analyse(read_joined([tmp_path / "r.txt"]), "r")
    assert len(imp.seg.steps) == 2 and [w.steps for w in imp.windows] == [(0,), (1,)]
    assert all(b.a == a.b for a, b in zip(imp.windows, imp.windows[1:]))  # disjoint, tiled
    for w in imp.windows:  # at the window's start, friction (noise-free) is at its steady value within two noise sigma
        v = w.velocities[0]
        mu_ss = TRUTH["mu0"] + (TRUTH["a"] - TRUTH["b"]) * np.log(v / 1e-6)
        assert abs(clean[lo + w.a] - mu_ss) < 2 * SIGMA, w.start_note
        assert "at steady state" in w.start_note
    # the record starts in the transient of the step before it, 4 sigma and more from steady: the old slicing
    # started the first window there
    assert abs(clean[lo] - (TRUTH["mu0"] + (TRUTH["a"] - TRUTH["b"]) * np.log(2.0))) > 4 * SIGMA
    assert imp.windows[0].a > 0
    joint = analyse(read_joined([tmp_path / "r.txt"]), "r", joint=True).windows[0]
    assert joint.a == imp.windows[0].a and joint.steps == (0, 1)  # the whole record from its first steady state


def test_a_piece_at_steady_state_is_steady_within_one_window_of_its_start(history):
    _, x, _, mu = history
    a, e = int(1400.0 / DT), int(3400.0 / DT)  # 200 um (4 Dc) after the step down and on: steady
    p = steady_point(x, mu, a, e, 0)  # steady from the start, up to a chance crossing within one window
    assert p.found and x[p.index] - x[a] <= p.window
    p = steady_point(x, mu, int(100.0 / DT) + 1, int(400.0 / DT), 1)  # just after the step up: a transient
    assert p.found and x[p.index] - x[int(100.0 / DT)] > TRUTH["Dc"] * 1e6


def test_the_command_joins_files_and_says_where_each_window_starts(tmp_path, history, capsys):
    t, x, _, mu = history
    _write(tmp_path / "a.txt", t, x, mu, 0, 3000)
    _write(tmp_path / "b.txt", t, x, mu, 2500, t.size)
    out = tmp_path / "out"
    out.mkdir()
    assert main(["datasets", "import", "velstep", str(tmp_path / "b.txt"), str(tmp_path / "a.txt"), "--name", "e",
                 "--out", str(out), "--steps", "3"]) == 0
    text = capsys.readouterr().out
    assert "a.txt+b.txt: 7400 samples" in text and text.count("at steady state") == 3
    d = load_dataset(out / "e-step2.toml")
    assert "the window starts at" in d.provenance.method and "b.txt" in d.provenance.method
    assert window(d).startswith("starts at a.txt line ") and "at steady state" in window(d)  # the report's sentence


def test_the_record_command_answers_for_a_record_of_one_law(tmp_path, history, capsys):
    t, x, _, mu = history
    _write(tmp_path / "r.txt", t, x, mu, int(CUT / DT), t.size)
    assert main(["record", str(tmp_path / "r.txt"), "--name", "r", "--laws", "rate-state-aging", "--no-joint",
                 "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "Does one parameter set describe the up and the down steps? Yes, for every law tested (aging)" in out
    assert out.count("at steady state") == 2 and "r-step1 (2 -> 0.2 um/s)" in out
