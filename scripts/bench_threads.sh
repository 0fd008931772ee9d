#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# What a frame loses on two threads, and whether the library or the
# machine loses it: build/bench_ab times the library as it is in build/ now
# (two file copies of build/libhbao.so, so that bench_ab has its two
# builds) on one thread alone, then as two one-thread processes side by
# side (what the machine's two cores cost each other: shared caches,
# memory), then on two threads. Prints each time, the side-by-side
# processes against the one alone, and two threads' wall time against half
# of one thread's CPU time; their quotient is the library's own share
# (threads started and joined at each stage, the last rows' imbalance).
# That share is an estimate: the one-thread cases are CPU time, which
# leaves out time the VM takes away, while two threads' is wall time; two
# processes each work on a whole frame where two threads share one; and
# the two processes do not start in step. bench_ab prints tenths of a
# millisecond, so a frame of a few milliseconds gives coarse ratios.
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
    case $argument in
    --threads | --threads=*)
        echo "$0: the thread counts are this script's (1, two of 1, and 2): leave out --threads" >&2
        exit 2
        ;;
    esac
done
rounds=${ROUNDS:-10}
calls=${CALLS:-3}
repeats=${REPEATS:-3}
bench_ab_count "$0" ROUNDS "$rounds" 3
bench_ab_count "$0" CALLS "$calls" 3
bench_ab_count "$0" REPEATS "$repeats" 2
library="$REPO/build/libhbao.so"
if [ ! -f "$library" ]; then
    echo "$0: $library missing: build the library first (cmake --build build)" >&2
    exit 1
fi
bench_ab_program
work=$(mktemp -d)
side=""
# a background bench_ab ignores the terminal's interrupt: stop it too
trap '[ -z "$side" ] || kill "$side" 2>/dev/null || true; rm -rf "$work"' EXIT
trap 'exit 130' INT
trap 'exit 143' TERM
cp "$library" "$work/first.so"
cp "$library" "$work/second.so"
# one_run OUTPUT THREADS [bench_ab options]
one_run() {
    local output=$1 threads=$2
    shift 2
    "$bench" "$work/first.so" "$work/second.so" --rounds "$rounds" --calls "$calls" \
        --threads "$threads" "$@" >"$output" 2>&1
}
# measure N [bench_ab options]: the three cases once, into $work/N.alone,
# .side_a, .side_b and .two
measure() {
    local n=$1
    shift
    one_run "$work/$n.alone" 1 "$@" || { cat "$work/$n.alone" >&2; exit 1; }
    one_run "$work/$n.side_a" 1 "$@" &
    side=$!
    one_run "$work/$n.side_b" 1 "$@" || { cat "$work/$n.side_b" >&2; exit 1; }
    wait "$side" || { side=""; cat "$work/$n.side_a" >&2; exit 1; }
    side=""
    one_run "$work/$n.two" 2 "$@" || { cat "$work/$n.two" >&2; exit 1; }
}
for ((n = 1; n <= repeats; n++)); do measure "$n" "$@"; done
python3 - "$work" "$repeats" "$rounds" "$calls" "$REPO/scripts" <<'PY'
import sys
from pathlib import Path
from statistics import median

sys.path.insert(0, sys.argv[5])
from bench_stats import bench_ab_result, bench_ab_settings  # noqa: E402  (scripts/bench_stats.py)

work, repeats = Path(sys.argv[1]), int(sys.argv[2])
rounds, calls = sys.argv[3], sys.argv[4]


def fastest(name, unit):
    """The mean of both builds' fastest calls (they are one library), in
    `unit` ms ("CPU" on one thread, "wall" on two)."""
    text = (work / name).read_text()
    found = bench_ab_result(text)
    if found is None or found[2] != unit:
        sys.exit(f"bench_threads.sh: no {unit} time in bench_ab's output:\n{text}")
    value = (found[0] + found[1]) / 2.0
    if value <= 0.0:
        sys.exit(f"bench_threads.sh: bench_ab timed {name} at 0.0 ms: give a larger --size")
    return value


turns = []
for n in range(1, repeats + 1):
    alone = fastest(f"{n}.alone", "CPU")
    side = [fastest(f"{n}.side_a", "CPU"), fastest(f"{n}.side_b", "CPU")]
    turns.append((alone, side, fastest(f"{n}.two", "wall")))
alone = median(t[0] for t in turns)
side = median(s for t in turns for s in t[1])
two = median(t[2] for t in turns)
side_ratio = median(s / t[0] for t in turns for s in t[1])
two_ratio = median(t[2] / (t[0] / 2.0) for t in turns)
# the settings without bench_ab's thread count: this script sets it per case
settings = ", ".join(item for item in bench_ab_settings((work / "1.alone").read_text()).split(", ")
                     if not item.endswith("thread(s)"))
print(f"bench_ab: {settings}, {rounds} rounds of {calls} calls; "
      f"the mean over rounds of the fastest call, median of {repeats} turns "
      "(ratios: the median of each turn's)")
print(f"one thread alone: {alone:.1f} CPU ms")
print(f"two one-thread processes side by side: {side:.1f} CPU ms each, {side_ratio:.3f}x alone "
      "(the machine's own contention)")
print(f"two threads: {two:.1f} wall ms, {two_ratio:.3f}x half of one thread alone "
      f"(the library's own share: about {two_ratio / side_ratio:.3f}x)")
PY
