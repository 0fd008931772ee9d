#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# The whole test suite, from a fresh Debian 12 machine:
#   1. install what is missing (scripts/setup.sh),
#   2. build (Release) and run the C tests (ctest),
#   3. build again with AddressSanitizer + UndefinedBehaviorSanitizer and run
#      the C tests and a mutation pass of the CLI under it; cross-build for
#      ARM64 and run the C tests under qemu-user (scripts/test_arm64.sh); then
#      60 s of the libFuzzer targets (scripts/fuzz.sh),
#   4. check PEP 8 of all Python code,
#   5. run the Python tests (pytest): the ctypes binding, the CLI on EXRs
#      written by Blender, the add-on in real headless and Xvfb Blender renders,
#      the GLSL viewport preview under Xvfb.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$REPO"
# shellcheck source=jobs.sh
. "$REPO/scripts/jobs.sh"
jobs_check test.sh
JOBS="${JOBS:-2}"
# Debian's Python, which has the numpy and pytest that setup.sh installs (a
# python3 earlier on PATH, e.g. pyenv's, may not).
PYTHON="${PYTHON:-/usr/bin/python3}"

# Each stage's wall time, printed as it ends and together when the run ends
# (passed or failed): where the suite's minutes go.
STAGE_NAME="setup (scripts/setup.sh, setup_bpy.sh)"
STAGE_START=$SECONDS
STAGE_TIMES=()
stage_end() {
    local seconds=$((SECONDS - STAGE_START))
    STAGE_TIMES+=("$(printf '%5d s  %s' "$seconds" "$STAGE_NAME")")
    echo "-- $STAGE_NAME: $seconds s"
}
stage() { # stage TITLE: ends the stage before and starts TITLE
    stage_end
    STAGE_NAME=$1
    STAGE_START=$SECONDS
    echo "== $1"
}
stage_summary() {
    local status=$?
    stage_end
    echo "== stage times (wall; $SECONDS s in all, exit status $status)"
    printf '%s\n' "${STAGE_TIMES[@]}"
}
trap stage_summary EXIT

"$REPO/scripts/setup.sh"
# PyPI's bpy 4.5 LTS, 5.0, 5.2 LTS and the newest 5.x for the Blender matrix (reused
# from ~/.cache/hbao/bpy between runs).
"$REPO/scripts/setup_bpy.sh"

stage "build (Release) and C tests"
# Options are given explicitly: a build folder configured earlier (e.g. by
# fuzz_cli.sh, which turns the tests off) keeps its cached values otherwise.
OPTIONS=(-DHBAO_BUILD_TOOL=ON -DHBAO_BUILD_TESTS=ON)
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DHBAO_SANITIZE=OFF -DHBAO_BUILD_BENCHMARKS=ON \
    "${OPTIONS[@]}" >/dev/null
cmake --build build -j"$JOBS"
ctest --test-dir build --output-on-failure --no-tests=error -j"$JOBS"

stage "build with AddressSanitizer + UndefinedBehaviorSanitizer and C tests"
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=Debug -DHBAO_SANITIZE=ON \
    -DHBAO_BUILD_BENCHMARKS=OFF "${OPTIONS[@]}" >/dev/null
cmake --build build-sanitize -j"$JOBS"
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
    ctest --test-dir build-sanitize --output-on-failure --no-tests=error -j"$JOBS"
# 100 mutations per fixture keep this step short; the script defaults to 500
scripts/fuzz_cli.sh 100 1

stage "ARM64: cross-built, C tests under qemu-user (the generic kernel on Advanced SIMD)"
scripts/test_arm64.sh

stage "coverage-guided fuzzing (libFuzzer + ASan + UBSan), 60 s"
scripts/fuzz.sh 60

stage "style: PEP 8 (Python), .clang-format (C)"
"$PYTHON" -m pycodestyle addon scripts tests $( [ -d bench ] && echo bench )
# shellcheck disable=SC2046
clang-format --dry-run --Werror $(git ls-files 'csrc/*.c' 'csrc/*.h')

stage "soak: a 50-frame animation with the node and 200 CLI runs (memory, time, leftovers)"
scripts/soak.sh --frames 50 --runs 200 --report out/soak/test-report.md

stage "Python tests (real Blender: Debian's blender and bpy 4.5, 5.0, 5.2, newest 5.x)"
# Debian's blender + the four bpy builds: a missing one fails the run. One
# pytest-xdist worker a job: most tests wait on one Blender's start and a
# small render, so two side by side took 0.6 of the time on 2 cores (a
# module whose module fixtures run Blender stays on one worker: loadgroup).
# A PYTHON without pytest-xdist (setup.sh installs Debian's) runs them one
# at a time.
WORKERS=(-n "$JOBS" --dist loadgroup)
if ! "$PYTHON" -c "import xdist" 2>/dev/null; then
    echo "test.sh: $PYTHON has no pytest-xdist: the Python tests run one at a time"
    WORKERS=()
fi
HBAO_EXPECTED_BLENDERS=5 "$PYTHON" -m pytest tests -q -p no:cacheprovider "${WORKERS[@]}"
