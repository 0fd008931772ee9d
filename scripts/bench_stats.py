# SPDX-License-Identifier: GPL-2.0-or-later
"""What the A/B benchmark scripts (bench_ab_pairs.sh, bench_blur_ab.sh)
print about a list of per-round ratios, and the median time of a function
that the Python benchmarks run inside Blender take."""
import statistics
import time


def quartiles(values):
    """The lower and upper quartile, as text (a single round has none)."""
    if len(values) < 2:
        return "none (one round)"
    low, _, high = statistics.quantiles(values, n=4)
    return f"{low:.3f}-{high:.3f}"


def median_ms(function, repeats, warm_up=False):
    """The median wall-clock milliseconds of `repeats` calls of `function()`,
    after one untimed call where `warm_up`."""
    if warm_up:
        function()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append((time.perf_counter() - start) * 1000.0)
    return statistics.median(times)
