# SPDX-License-Identifier: GPL-2.0-or-later
"""What the A/B benchmark scripts (bench_ab_pairs.sh, bench_blur_ab.sh)
print about a list of per-round ratios."""
import statistics


def quartiles(values):
    """The lower and upper quartile, as text (a single round has none)."""
    if len(values) < 2:
        return "none (one round)"
    low, _, high = statistics.quantiles(values, n=4)
    return f"{low:.3f}-{high:.3f}"
