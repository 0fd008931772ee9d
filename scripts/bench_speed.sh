#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# The speed benchmark of the C library (issue 11): builds a Release build and
# prints ms per frame for the settings issue 11 sets targets for (the
# defaults at 1920x1080 full and half resolution, 8 x 6 with a 15-pixel blur,
# the defaults at 3840x2160), one column per implementation this CPU has
# (scalar on 1 thread; the generic kernel, AVX2 and AVX-512 on 1 and 2
# threads), the blur's share
# and the targets beside the medians. With the default 5 runs it takes a few
# minutes, most of it in the scalar column.
#   scripts/bench_speed.sh [--runs N] [--implementations scalar,generic,avx2,avx512] [--no-4k]
#                          [--quick]
#                          [--radius R]      (--quick = --runs 3 --no-4k)
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$REPO/scripts/setup.sh"
cmake -S "$REPO" -B "$REPO/build" -DCMAKE_BUILD_TYPE=Release -DHBAO_BUILD_BENCHMARKS=ON >/dev/null
cmake --build "$REPO/build" -j2 --target bench_speed >/dev/null
exec "$REPO/build/bench_speed" "$@"
