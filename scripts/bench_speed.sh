#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# The speed benchmark of the C library (issue 2): builds a Release build and
# prints ms per 1920x1080 frame for 4/8/16 directions x 4/6/8 steps, full and
# half resolution, blur 0 and 15, scalar 1 thread vs the SIMD kernel on 1 and
# 2 threads (median of 3 runs; a full run takes about ten minutes).
#   scripts/bench_speed.sh [--quick] [--runs N] [--radius R] [--width W --height H]
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$REPO/scripts/setup.sh"
cmake -S "$REPO" -B "$REPO/build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$REPO/build" -j2 --target bench_speed >/dev/null
exec "$REPO/build/bench_speed" "$@"
