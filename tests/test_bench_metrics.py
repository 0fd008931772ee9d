# SPDX-License-Identifier: GPL-2.0-or-later
"""bench/metrics.py's equal-error reading of a Cycles series (the 480x270
and 1080p benchmarks' Cycles / HBAO ratios rest on it): the least whole
sample count whose render reaches an RMSE, the fraction read log-log
linear between two measured counts, and Cycles' time there. Plain pytest,
no Blender."""
import math
import sys

import pytest

from conftest import REPO

sys.path.insert(0, str(REPO / "bench"))
import metrics  # noqa: E402


def power_law(samples, a=0.26, exponent=0.75):
    return a * samples ** -exponent


# Cycles' error at a few samples falls faster than 1 / sqrt(samples); on a
# power law the reading is exact anywhere between two measured counts.
SERIES = [(n, power_law(n)) for n in (1, 2, 4, 8, 16)]


@pytest.mark.parametrize("samples", [1.0, 1.5, 2.0, 3.0, 5.7, 8.0, 11.3, 16.0])
def test_a_count_between_measured_ones_is_read_off_the_line(samples):
    found = metrics.samples_for_rmse(SERIES, power_law(samples))
    assert found == pytest.approx(samples, rel=1e-9)


def test_the_two_bracketing_counts_decide_not_a_fit_to_all():
    # the series bends: exponent 1 up to 4 samples, 0.5 beyond; a count
    # between 8 and 16 follows the 0.5 of its own neighbours
    series = [(1, 0.4), (2, 0.2), (4, 0.1), (8, 0.1 / math.sqrt(2)), (16, 0.05)]
    expected = 8 * (0.1 / math.sqrt(2) / 0.06) ** 2
    assert metrics.samples_for_rmse(series, 0.06) == pytest.approx(expected)
    assert metrics.samples_for_rmse(series, 0.3) == pytest.approx(1 / 0.75)


def test_an_rmse_that_one_sample_reaches_takes_one():
    assert metrics.samples_for_rmse(SERIES, power_law(1) * 1.5) == 1.0
    assert metrics.samples_for_rmse(SERIES, power_law(1)) == 1.0


def test_beyond_the_series_the_last_two_counts_extend():
    assert metrics.samples_for_rmse(SERIES, power_law(64)) == pytest.approx(64, rel=1e-9)


def test_the_series_may_come_in_any_order():
    assert metrics.samples_for_rmse(SERIES[::-1], power_law(6)) == pytest.approx(6, rel=1e-9)


def test_cycles_time_is_read_off_its_line_and_at_least_its_fastest_render():
    # seconds = 0.5 + 0.25 samples
    series = [(n, 0.5 + 0.25 * n) for n, _ in SERIES]
    assert metrics.cycles_seconds_at(series, 6.3) == pytest.approx(0.5 + 0.25 * 6.3)
    assert metrics.cycles_seconds_at([(1, 1.0), (2, 1.1), (4, 1.3)], 0.0) == pytest.approx(1.0)


def test_the_last_two_counts_extend_the_series_bent_or_not():
    series = [(1, 0.4), (2, 0.2), (4, 0.1), (8, 0.1 / math.sqrt(2)), (16, 0.05)]
    assert metrics.samples_for_rmse(series, 0.025) == pytest.approx(64)


@pytest.mark.parametrize("points, target", [
    ([(4, 0.1)], 0.05),  # one count
    ([(4, 0.1), (4, 0.09)], 0.05),  # the same count twice
    ([(1, 0.2), (2, 0.1), (4, 0.12)], 0.05),  # rising where it would extend
    ([(1, 0.2), (2, 0.2)], 0.3 / 2),  # not falling
    ([(1, 0.2), (2, 0.0)], 0.05),  # an RMSE of 0
    ([(1, 0.2), (2, 0.1)], 0.0),  # a target of 0
])
def test_points_that_give_no_count_are_refused(points, target):
    with pytest.raises(ValueError):
        metrics.samples_for_rmse(points, target)


def test_a_series_that_starts_past_one_sample_extends_down_to_one():
    assert metrics.samples_for_rmse([(4, 0.1), (8, 0.05)], 0.2) == pytest.approx(2.0)
    assert metrics.samples_for_rmse([(4, 0.1), (8, 0.05)], 0.5) == 1.0  # 0.8, at least 1


class Renders:
    """A stand-in for Cycles' renders: RMSE at n samples, and the counts asked."""

    def __init__(self, rmse):
        self.rmse, self.asked = rmse, []

    def __call__(self, samples):
        self.asked.append(samples)
        return self.rmse[samples]


# Powers of 2 do best, as with Cycles' sampler: 9 falls short of 8.
UNEVEN = {1: 0.38, 2: 0.23, 3: 0.18, 4: 0.14, 5: 0.125, 6: 0.11, 7: 0.1, 8: 0.084,
          9: 0.0836, 10: 0.078, 11: 0.0742, 12: 0.07, 13: 0.066, 14: 0.063, 15: 0.06, 16: 0.0514}


def test_the_equal_error_count_is_the_least_whole_count_that_reaches_it():
    renders = Renders(UNEVEN)
    count, whole = metrics.equal_error_count(renders, 0.0707, 64)
    # 12 reaches 0.0707 and 11 does not, though 8 and 16 put it near 10
    assert whole == 12
    assert 11 < count <= 12
    assert count == pytest.approx(metrics.samples_for_rmse([(11, 0.0742), (12, 0.07)], 0.0707))
    assert max(renders.asked) == 16  # the first power of 2 that reaches it bounds the search
    assert 13 not in renders.asked


def test_a_count_that_reaches_it_before_one_that_does_not_is_found():
    # 5 reaches 0.105 though 6 does not
    renders = Renders({**UNEVEN, 5: 0.104})
    assert metrics.equal_error_count(renders, 0.105, 64)[1] == 5
    assert metrics.equal_error_count(Renders(UNEVEN), 0.5, 64) == (1.0, 1)


def test_a_target_beyond_the_most_samples_is_refused():
    with pytest.raises(ValueError):
        metrics.equal_error_count(Renders(UNEVEN), 0.01, 16)
