#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Two builds of libhbao compared on a machine whose speed drifts by tens of
# per cent over minutes (a shared VM, where the neighbours' memory traffic
# moves a memory-bound loop): bench_ab with one call of each build per
# round (--calls 1), so that the two calls of a round see the same machine,
# in both orders (the second call of a round runs a few per cent slower).
# Prints the settings bench_ab ran with (the thread count included: bench_ab
# runs on 1 thread unless --threads says otherwise), then the median over
# the rounds of each round's after / before ratio, for each order, and their
# geometric mean (the order's bias cancelled), and the quartiles of each
# order's per-round ratios.
#   scripts/bench_ab_pairs.sh BEFORE.so AFTER.so [bench_ab options]
# Environment: ROUNDS (per order, default 30). scripts/bench_ab_copies.sh
# is the steadier choice where the machine's speed holds still.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# shellcheck source=bench_ab_setup.sh
. "$REPO/scripts/bench_ab_setup.sh"
bench_ab_arguments "$0" "$@"
shift 2
rounds=${ROUNDS:-30}
bench_ab_count "$0" ROUNDS "$rounds" 3
bench_ab_program
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$bench" "$before" "$after" --rounds "$rounds" --calls 1 "$@" >"$work/forward" 2>&1 ||
    { cat "$work/forward" >&2; exit 1; }
"$bench" "$after" "$before" --rounds "$rounds" --calls 1 "$@" >"$work/reverse" 2>&1 ||
    { cat "$work/reverse" >&2; exit 1; }
python3 - "$work/forward" "$work/reverse" "$*" "$REPO/scripts" <<'PY'
import math
import statistics
import sys

sys.path.insert(0, sys.argv[4])
from bench_stats import bench_ab_settings, quartiles  # noqa: E402  (scripts/bench_stats.py)


def ratios(path):
    """Each round's second-named / first-named fastest call."""
    first, second = [], []
    for line in open(path, encoding="utf-8"):
        fields = line.split()
        if len(fields) >= 4 and fields[0] == "round":
            (first if fields[2] == "before" else second).append(float(fields[3]))
    if not first or len(first) != len(second):
        sys.exit(f"bench_ab_pairs.sh: no rounds in {path}")
    return [b / a for a, b in zip(first, second)]


print(f"bench_ab: {bench_ab_settings(open(sys.argv[1], encoding='utf-8').read())}")
forward_rounds = ratios(sys.argv[1])
reverse_rounds = [1.0 / ratio for ratio in ratios(sys.argv[2])]
forward = statistics.median(forward_rounds)
reverse = statistics.median(reverse_rounds)
options = f" [{sys.argv[3]}]" if sys.argv[3] else ""
print(f"after / before{options}: {forward:.3f} (after second), {reverse:.3f} (after first)"
      f" -> {math.sqrt(forward * reverse):.3f}")
# Where the quartiles of the rounds' ratios are far apart, or the two
# orders' medians disagree, the machine drifted: run again with more ROUNDS.
print(f"rounds' quartiles: {quartiles(forward_rounds)} (after second), "
      f"{quartiles(reverse_rounds)} (after first)")
PY
