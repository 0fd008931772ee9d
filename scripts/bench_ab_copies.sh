#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Two builds of libhbao compared the way session 10 kept or dropped its
# changes: on this machine two file copies of the same library time a steady
# 3-5 % apart (where the pages land in memory), so one bench_ab run of one
# copy of each build is worth +-5 %. This makes COPIES copies of each
# library, runs bench_ab once per pair (every other run in the reverse
# order), and prints each run's after / before ratio (fastest call) and
# their mean. Extra arguments go to bench_ab (--threads, --half, ...).
#   scripts/bench_ab_copies.sh BEFORE.so AFTER.so [bench_ab options]
# Environment: COPIES (default 4), ROUNDS (bench_ab --rounds, default 3).
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# shellcheck source=bench_ab_setup.sh
. "$REPO/scripts/bench_ab_setup.sh"
bench_ab_arguments "$0" "$@"
shift 2
copies=${COPIES:-4}
rounds=${ROUNDS:-3}
bench_ab_count "$0" COPIES "$copies" 2
bench_ab_count "$0" ROUNDS "$rounds" 2
bench_ab_program
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# One bench_ab run; prints its fastest-call after / before ratio, or stops
# the script with bench_ab's own message when it fails.
ratio_of_run() {
    local output
    if ! output=$("$bench" "$1" "$2" --rounds "$rounds" "${@:3}" 2>&1); then
        echo "$output" >&2
        echo "$0: bench_ab failed (above)" >&2
        exit 1
    fi
    sed -n 's/.*after \/ before \([0-9.]*\) .*/\1/p' <<<"$output" | tail -n 1
}

ratios=()
for i in $(seq 1 "$copies"); do
    cp "$before" "$work/before_$i.so"
    cp "$after" "$work/after_$i.so"
    if [ $((i % 2)) = 1 ]; then
        r=$(ratio_of_run "$work/before_$i.so" "$work/after_$i.so" "$@")
    else # reversed: the ratio is before / after, inverted
        r=$(ratio_of_run "$work/after_$i.so" "$work/before_$i.so" "$@")
        [ -n "$r" ] && r=$(awk -v r="$r" 'BEGIN { printf "%.3f", 1 / r }')
    fi
    if [ -z "$r" ]; then
        echo "$0: bench_ab printed no ratio (run it alone to see why)" >&2
        exit 1
    fi
    ratios+=("$r")
done
printf 'after / before [%s]: %s -> mean %s\n' "$*" "${ratios[*]}" \
    "$(printf '%s\n' "${ratios[@]}" | awk '{ s += $1 } END { printf "%.3f", s / NR }')"
