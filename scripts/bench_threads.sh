#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# What a frame loses on two threads, and whether the library or the
# machine loses it: build/bench_ab times the library (two file copies of
# build/libhbao.so, so that bench_ab has its two builds) on one thread
# alone, then as two one-thread processes side by side (what the machine's
# two cores cost each other: shared caches, memory, the VM's neighbours),
# then on two threads. Prints each time, the side-by-side processes against
# the one alone, and two threads' wall time against half of one thread's
# CPU time: the part of that beyond the side-by-side ratio is the library's
# own (threads started and joined at each stage, the last rows' imbalance).
# docs/speed.md, session 51.
#   scripts/bench_threads.sh [bench_ab options, not --threads]
# The three cases run in turn REPEATS times, so that the VM's drift from
# minute to minute falls on all three; each figure is the median over the
# turns. Environment: ROUNDS (bench_ab --rounds, default 10), CALLS
# (--calls, default 3), REPEATS (default 3).
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# shellcheck source=bench_ab_setup.sh
. "$REPO/scripts/bench_ab_setup.sh"
for argument in "$@"; do
    if [ "$argument" = --threads ]; then
        echo "$0: the thread counts are this script's (1, two of 1, and 2): leave out --threads" >&2
        exit 2
    fi
done
rounds=${ROUNDS:-10}
calls=${CALLS:-3}
repeats=${REPEATS:-3}
bench_ab_count "$0" ROUNDS "$rounds" 3
bench_ab_count "$0" CALLS "$calls" 3
bench_ab_count "$0" REPEATS "$repeats" 2
bench_ab_program
library="$REPO/build/libhbao.so"
if [ ! -f "$library" ]; then
    echo "$0: $library missing: build the library first (cmake --build build)" >&2
    exit 1
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp "$library" "$work/first.so"
cp "$library" "$work/second.so"
measure() { # measure N: the three cases once, into $work/N.alone, .side_a, .side_b, .two
    local n=$1
    shift
    "$bench" "$work/first.so" "$work/second.so" --rounds "$rounds" --calls "$calls" \
        --threads 1 "$@" >"$work/$n.alone" 2>&1 || { cat "$work/$n.alone" >&2; exit 1; }
    "$bench" "$work/first.so" "$work/second.so" --rounds "$rounds" --calls "$calls" \
        --threads 1 "$@" >"$work/$n.side_a" 2>&1 &
    local side=$!
    "$bench" "$work/first.so" "$work/second.so" --rounds "$rounds" --calls "$calls" \
        --threads 1 "$@" >"$work/$n.side_b" 2>&1 ||
        { wait "$side" || true; cat "$work/$n.side_b" >&2; exit 1; }
    wait "$side" || { cat "$work/$n.side_a" >&2; exit 1; }
    "$bench" "$work/first.so" "$work/second.so" --rounds "$rounds" --calls "$calls" \
        --threads 2 "$@" >"$work/$n.two" 2>&1 || { cat "$work/$n.two" >&2; exit 1; }
}
for ((n = 1; n <= repeats; n++)); do measure "$n" "$@"; done
python3 - "$work" "$repeats" "$*" <<'PY'
import re
import statistics
import sys
from pathlib import Path

work, repeats = Path(sys.argv[1]), int(sys.argv[2])


def fastest(name):
    """The mean over rounds of both builds' fastest calls (they are one
    library), and its unit."""
    text = (work / name).read_text()
    match = re.search(r"fastest / lower quartile: before ([0-9.]+) / [0-9.]+, "
                      r"after ([0-9.]+) / [0-9.]+ (CPU|wall) ms", text)
    if match is None:
        sys.exit(f"bench_threads: no timing line in bench_ab's output:\n{text}")
    return (float(match.group(1)) + float(match.group(2))) / 2.0, match.group(3)


turns = []
for n in range(1, repeats + 1):
    alone = fastest(f"{n}.alone")[0]
    side = [fastest(f"{n}.side_a")[0], fastest(f"{n}.side_b")[0]]
    two, unit = fastest(f"{n}.two")
    turns.append((alone, side, two, unit))
median = statistics.median
alone = median(t[0] for t in turns)
side = median(s for t in turns for s in t[1])
two = median(t[2] for t in turns)
side_ratio = median(s / t[0] for t in turns for s in t[1])
two_ratio = median(t[2] / (t[0] / 2.0) for t in turns)
print(f"bench_threads: build/bench_ab {sys.argv[3] or '(the defaults)'}; the mean over rounds "
      f"of the fastest call, median of {repeats} turns (ratios: median of each turn's)")
print(f"one thread alone: {alone:.1f} CPU ms")
print(f"two one-thread processes side by side: {side:.1f} CPU ms each, {side_ratio:.3f}x alone "
      "(the machine's own contention)")
print(f"two threads: {two:.1f} {turns[0][3]} ms, {two_ratio:.3f}x half of one thread alone "
      f"(the library's own share: about {two_ratio / side_ratio:.3f}x)")
PY
