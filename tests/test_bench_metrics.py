# SPDX-License-Identifier: GPL-2.0-or-later
"""bench/metrics.py's equal-error reading of a Cycles series (the 480x270
and 1080p benchmarks' Cycles / HBAO ratios rest on it): the sample count
for an RMSE, read log-log linear between the two measured counts that
bracket it. Plain pytest, no Blender."""
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


def test_cycles_time_is_read_at_that_count():
    # seconds = 0.5 + 0.25 samples
    series = [(n, 0.5 + 0.25 * n, rmse) for n, rmse in SERIES]
    samples, seconds = metrics.cycles_time_for_rmse(series, power_law(6))
    assert samples == pytest.approx(6, rel=1e-9)
    assert seconds == pytest.approx(0.5 + 0.25 * 6, rel=1e-9)
