#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Two builds of the blur stage against each other: each round runs both
# builds' bench_blur (csrc/bench/bench_blur.c; build/bench_blur of a build
# configured with -DHBAO_BUILD_BENCHMARKS=ON) once, in turns, the first of
# them alternating from round to round (the second run of a round is a few
# per cent slower on a shared VM), and takes each run's fastest call.
# Prints the median of the rounds' after / before ratios with their
# quartiles, each build's median, and whether the two builds' outputs are
# bit-identical (the same hash of their bits).
#   scripts/bench_blur_ab.sh BEFORE/bench_blur AFTER/bench_blur [bench_blur options]
# Environment: ROUNDS (default 20). bench_blur's --calls defaults to 5 here.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# shellcheck source=bench_ab_setup.sh
. "$REPO/scripts/bench_ab_setup.sh"
if [ $# -lt 2 ] || [ ! -x "$1" ] || [ ! -x "$2" ]; then
    echo "usage: $0 BEFORE/bench_blur AFTER/bench_blur [bench_blur options]" >&2
    exit 2
fi
before=$1
after=$2
shift 2
rounds=${ROUNDS:-20}
bench_ab_count "$0" ROUNDS "$rounds" 3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
run() { # run BUILD FILE: one bench_blur run, its line appended to FILE
    "$1" --calls 5 "${@:3}" >>"$2" 2>"$work/error" ||
        { echo "$0: $1 failed:" >&2; cat "$work/error" >&2; exit 1; }
}
for ((round = 0; round < rounds; round++)); do
    if ((round % 2)); then
        run "$after" "$work/after" "$@"
        run "$before" "$work/before" "$@"
    else
        run "$before" "$work/before" "$@"
        run "$after" "$work/after" "$@"
    fi
done
python3 - "$work/before" "$work/after" "$REPO/scripts" "$before" "$after" "$rounds" <<'PY'
import re
import statistics
import sys

sys.path.insert(0, sys.argv[3])
from bench_stats import quartiles  # noqa: E402  (scripts/bench_stats.py)

rounds = int(sys.argv[6])


def runs(path):
    """Each run's fastest CPU ms and output hash, and the settings line."""
    with open(path, encoding="utf-8") as lines:
        text = [line for line in lines.read().splitlines() if line.startswith("bench_blur ")]
    if len(text) != rounds or not all("fastest " in line and "output hash " in line
                                      for line in text):
        sys.exit(f"bench_blur_ab.sh: {sys.argv[4 + (path == sys.argv[2])]} did not print "
                 "bench_blur's result line: is it build/bench_blur?")
    fastest = [float(re.search(r"fastest ([\d.]+)", line).group(1)) for line in text]
    checksums = {re.search(r"output hash (\S+)", line).group(1) for line in text}
    return fastest, checksums, text[0].split(":")[0]


before, before_sums, settings = runs(sys.argv[1])
after, after_sums, _ = runs(sys.argv[2])
ratios = [a / b for a, b in zip(after, before)]
print(settings)
print(f"fastest CPU ms, median of {len(ratios)} rounds: before "
      f"{statistics.median(before):.2f}, after {statistics.median(after):.2f}")
print(f"after / before: {statistics.median(ratios):.3f} (rounds' quartiles "
      f"{quartiles(ratios)})")
same = before_sums == after_sums and len(before_sums) == 1
print("outputs: " + ("bit-identical (the same hash)" if same else
                     f"differ: hashes {sorted(before_sums)} / {sorted(after_sums)}"))
PY
