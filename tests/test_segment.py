"""The piecewise-linear segmentation of load-point displacement (frictionlab.io.segment) on records of known
truth: the number of steps chosen by the data, step times and velocities within their standard errors, holds,
resets, and refusals of what is not straight pieces."""
from __future__ import annotations

import numpy as np
import pytest

from frictionlab.core.errors import DatasetError
from frictionlab.io.segment import MIN_PIECE, segment


def piecewise(t, knots, velocities):
    """Displacement of a load point moving at velocities[i] from knots[i-1] to knots[i] (continuous)."""
    edges = [t[0], *knots, np.inf]
    return sum(v * np.clip(t - a, 0.0, b - a) for (a, b), v in zip(zip(edges[:-1], edges[1:]), velocities))


def ar1(rng, n, phi, sigma):
    e = rng.normal(0.0, sigma, n)
    out = np.empty(n)
    out[0] = e[0] / np.sqrt(1 - phi * phi)
    for i in range(1, n):
        out[i] = phi * out[i - 1] + e[i]
    return out


T = np.arange(3000) * 0.1


def one_step_z(noise: str, seed: int) -> tuple[float, list[float]]:
    """A record of one step (1 -> 3 um/s near 150 s; white noise or AR(1) noise of coefficient 0.9) segmented:
    (estimate - truth) / standard error of the step time, and of the two velocities. Exactly one step is found."""
    rng = np.random.default_rng(seed)
    ts = 150.0 + rng.uniform(0, 0.1)
    e = rng.normal(0, 0.1, T.size) if noise == "white" else ar1(rng, T.size, 0.9, 0.05)
    s = segment(T, piecewise(T, [ts], [1.0, 3.0]) + e)
    assert len(s.steps) == 1
    return (s.steps[0].time - ts) / s.steps[0].time_se, \
        [(v - truth) / se for v, truth, se in zip(s.velocities, (1.0, 3.0), s.velocities_se)]


@pytest.mark.parametrize("noise", ["white", "ar1"])
def test_each_step_time_and_velocity_is_within_four_standard_errors_of_the_truth(noise):
    """Five records of the calibration below, each on its own: one step, found within 4 standard errors."""
    for seed in range(5):
        z, zv = one_step_z(noise, seed)
        assert abs(z) < 4 and max(map(abs, zv)) < 4, (seed, z, zv)


@pytest.mark.slow
@pytest.mark.parametrize("noise", ["white", "ar1"])
def test_step_times_and_velocities_agree_with_the_truth_within_their_errors(noise):
    """Over 30 records, the step time lands within its standard error as often as a normal variable does (the
    rms of (estimate - truth) / error near 1), with AR(1) noise of coefficient 0.9 too (a calibration: run by
    ``python benchmarks/calibration_segment.py``)."""
    z, zv = [], []
    for seed in range(30):
        zt, zvs = one_step_z(noise, seed)
        z.append(zt)
        zv += zvs
    assert 0.6 < np.sqrt(np.mean(np.square(z))) < 1.5, z
    assert np.sqrt(np.mean(np.square(zv))) < 1.5, zv


@pytest.mark.parametrize("phi", [0.0, 0.9, 0.99])
@pytest.mark.parametrize("records", [5, pytest.param(40, marks=pytest.mark.slow)])
def test_a_record_without_a_step_is_refused_not_cut_into_pieces(phi, records):
    """Pure noise about one line, white or strongly correlated: the data choose no step (5 records each; 40 in
    the calibration run by ``python benchmarks/calibration_segment.py``)."""
    for seed in range(records):
        rng = np.random.default_rng(seed)
        e = rng.normal(0, 0.1, T.size) if phi == 0 else ar1(rng, T.size, phi, 0.05)
        with pytest.raises(DatasetError, match="no velocity step found: the displacement is one straight line"):
            segment(T, piecewise(T, [], [1.0]) + e, "rec")


@pytest.mark.parametrize("knots, vs", [([50.0, 100.0, 180.0, 240.0], [1.0, 10.0, 1.0, 3.0, 0.3]),  # a staircase
                                       ([50.0, 150.0, 180.0, 250.0], [3.0, 0.0, 3.0, 0.0, 3.0])])  # slide-hold-slide
def test_the_number_of_steps_is_chosen_by_the_data_and_holds_are_steps(knots, vs):
    rng = np.random.default_rng(1)
    s = segment(T, piecewise(T, knots, vs) + rng.normal(0, 0.05, T.size))
    assert [round(st.time, 1) for st in s.steps] == knots
    assert np.allclose(s.velocities, vs, rtol=1e-3, atol=1e-3)


def test_a_small_step_is_found_and_its_time_is_not_moved_to_a_sample():
    rng = np.random.default_rng(3)
    s = segment(T, piecewise(T, [150.037], [1.0, 1.2]) + rng.normal(0, 0.02, T.size))
    (st,) = s.steps
    assert abs(st.time - 150.037) < 4 * st.time_se and round(st.time, 1) != st.time


def test_a_transducer_reset_is_stitched_not_taken_for_a_step():
    """A 5000 um jump without a change of velocity, then a real step: one step, one jump stitched."""
    rng = np.random.default_rng(4)
    x = piecewise(T, [250.0], [3.33, 10.0]) + rng.normal(0, 0.05, T.size)
    x[T >= 120.0] += 5000.0
    s = segment(T, x)
    assert len(s.steps) == 1 and abs(s.steps[0].time - 250.0) < 4 * s.steps[0].time_se
    (j,) = s.jumps
    assert T[j.index] == pytest.approx(120.0) and j.size == pytest.approx(5000.0, abs=5 * j.size_se)
    assert np.allclose(s.velocities, (3.33, 10.0), rtol=1e-3)
    assert np.max(np.abs(np.diff(s.x))) < 10  # the stitched displacement is continuous


def test_a_reset_alone_is_no_step_and_is_named():
    rng = np.random.default_rng(5)
    x = piecewise(T, [], [3.33]) + rng.normal(0, 0.05, T.size)
    x[T >= 120.0] += 5000.0
    with pytest.raises(DatasetError, match=r"no velocity step found.*a jump of 5000 at line 1201 \(t = 120 s\) stitched"):
        segment(T, x, "rec")


def test_correlated_wander_is_no_jump_and_a_servo_correction_on_it_is_one():
    """Three samples standing off the three before are weighed against the noise of that difference: AR(0.99) wander
    alone (which moves neighbouring samples together) has no jump stitched, while a 1 um correction at 120 s on
    AR(0.9) noise is stitched there, and only there."""
    for seed in range(100, 110):
        rng = np.random.default_rng(seed)
        with pytest.raises(DatasetError, match="no velocity step found") as wander:
            segment(T, piecewise(T, [], [1.0]) + ar1(rng, T.size, 0.99, 0.05), "rec")
        assert "jump" not in str(wander.value)
        x = piecewise(T, [], [1.0]) + ar1(rng, T.size, 0.9, 0.05)
        x[T >= 120.0] += 1.0
        with pytest.raises(DatasetError, match=r"no velocity step found[^;]*; a jump of [\d.]+ at line 1201 "
                                               r"\(t = 120 s\) stitched$"):
            segment(T, x, "rec")


@pytest.mark.parametrize("at, side", [(3, "after the start of the record"), (T.size - 2, "before the end of the record"),
                                      (MIN_PIECE - 5, "after the start of the record")])
def test_a_step_too_near_either_end_is_refused_by_what_it_is(at, side):
    rng = np.random.default_rng(6)
    x = piecewise(T, [T[at] - 0.05], [1.0, 10.0]) + rng.normal(0, 0.05, T.size)
    with pytest.raises(DatasetError, match=rf"rec: the velocity changes at line \d+ .*samples? {side}; a step needs "
                                           rf"at least {MIN_PIECE} samples of each velocity"):
        segment(T, x, "rec", line=lambda i: i + 2)


@pytest.mark.parametrize("x", [50 * (1 - np.exp(-T / 30)), 0.01 * T ** 2, 20 * np.sin(T / 50)])
def test_a_curved_displacement_is_refused_as_not_straight(x):
    rng = np.random.default_rng(7)
    with pytest.raises(DatasetError, match=r"rec: the displacement from line \d+ .* to line \d+ .* is not a straight "
                                           r"line: it strays .* times its noise"):
        segment(T, x + rng.normal(0, 0.05, T.size), "rec")


def test_a_servo_wander_slower_than_the_sampling_is_not_a_step():
    """A 0.5 um oscillation of 20 s period on both pieces: one step, at its time."""
    rng = np.random.default_rng(8)
    x = piecewise(T, [150.0], [1.0, 3.0]) + 0.5 * np.sin(2 * np.pi * T / 20) + rng.normal(0, 0.1, T.size)
    (st,) = segment(T, x).steps
    assert abs(st.time - 150.0) < 4 * st.time_se


def test_a_long_record_is_segmented_on_a_grid_and_refined_to_the_sample():
    """200 000 samples (more than GRID): the step is still placed between the right samples."""
    t = np.arange(200_000) * 0.1
    rng = np.random.default_rng(9)
    s = segment(t, piecewise(t, [10000.03], [1.0, 10.0]) + rng.normal(0, 0.05, t.size))
    (st,) = s.steps
    assert st.index == 100001 and abs(st.time - 10000.03) < 4 * st.time_se


def test_twenty_steps_up_and_down_are_twenty_steps_at_their_times():
    """Steps every 95 s between 1 and 10 um/s: the noise is measured between them, so they are not noise."""
    t = np.arange(19950) * 0.1
    knots = [95.0 * k for k in range(1, 21)]
    rng = np.random.default_rng(10)
    s = segment(t, piecewise(t, knots, [1.0 if k % 2 == 0 else 10.0 for k in range(21)]) + rng.normal(0, 0.05, t.size))
    assert len(s.steps) == 20 and 0.04 < s.noise < 0.06
    assert all(abs(st.time - k) < 4 * st.time_se for st, k in zip(s.steps, knots))


def test_a_displacement_in_counts_is_straight_and_its_step_within_its_error():
    """0.1 um a sample read in counts of 0.5 um (a staircase): one step, the count's rounding as its noise."""
    z = []
    for seed in range(5):
        rng = np.random.default_rng(seed)
        ts = 150.0 + rng.uniform(0, 0.1)
        x = np.round((piecewise(T, [ts], [1.0, 3.0]) + rng.normal(0, 0.05, T.size)) / 0.5) * 0.5
        (st,) = segment(T, x).steps
        z.append((st.time - ts) / st.time_se)
    assert np.max(np.abs(z)) < 4, z


def test_a_record_without_noise_has_errors_that_bound_its_rounding():
    """Lines sampled exactly and written to 4 decimals: every sample after the step rounds alike, so the step
    time errs by up to half a digit over the change of velocity; its standard error says at least that."""
    t = np.arange(3000) * 0.01
    x = np.round(1554.674 + piecewise(t, [15.00333], [3.0, 10.0]), 4)
    s = segment(t, x)
    (st,) = s.steps
    assert s.exact_to == pytest.approx(1e-4) and st.time_se >= 0.5e-4 / 7 and abs(st.time - 15.00333) < st.time_se
