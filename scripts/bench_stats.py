# SPDX-License-Identifier: GPL-2.0-or-later
"""What the A/B benchmark scripts (bench_ab_pairs.sh, bench_blur_ab.sh,
bench_threads.sh, bench_search_parts.py) read from build/bench_ab's output
and print about a list of per-round ratios, and the median time of a
function that the Python benchmarks run inside Blender take."""
import re
import statistics
import time

# bench_ab's closing line: the mean over rounds of each build's fastest and
# lower-quartile call, what it times, and their after / before ratios
_BENCH_AB_RESULT = re.compile(r"fastest / lower quartile: before ([0-9.]+) / [0-9.]+, "
                              r"after ([0-9.]+) / [0-9.]+ (CPU|wall) ms; "
                              r"after / before ([0-9.]+) /")


def bench_ab_result(output):
    """(before's fastest ms, after's fastest ms, "CPU" or "wall", after /
    before) from bench_ab's output, or None where it printed no result."""
    found = _BENCH_AB_RESULT.search(output)
    if found is None:
        return None
    return float(found.group(1)), float(found.group(2)), found.group(3), float(found.group(4))


def bench_ab_settings(output):
    """bench_ab's first line up to its ';': size, directions x steps, blur,
    half resolution, back faces and background where set, radius and
    threads."""
    return output.split("\n", 1)[0].split(";")[0].strip()


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
