#!/bin/sh
# SPDX-License-Identifier: GPL-2.0-or-later
# Coverage-guided fuzzing (libFuzzer, AddressSanitizer, UndefinedBehaviorSanitizer)
# of the three fuzz targets in csrc/fuzz:
#   fuzz_exr_compute  an EXR through pass lookup, camera and hbao_compute (AO in [0, 1])
#   fuzz_keep_input   the whole `hbao IN -o OUT --keep-input --preview P` command
#   fuzz_camera_json  the camera JSON parser
#
#   scripts/fuzz.sh [SECONDS]        (default 60, shared between the targets)
#
# Builds build-fuzz/ with clang (cmake -DHBAO_BUILD_FUZZERS=ON), then runs each
# target on one core for its share of SECONDS: 40% each for the two EXR
# targets, 20% for the JSON parser, which runs ~100x more inputs per second.
# The targets run side by side, $JOBS (2) at a time: on 2 cores the run takes
# 60% of SECONDS.
# Seeds: tests/fixtures and csrc/fuzz/corpus/<target> (kept in the repository);
# what a run learns goes to build-fuzz/fuzz-corpus/<target>, so later runs
# start from there. Prints executions per target and in total; a finding (crash,
# sanitizer report, oracle abort, timeout, leak, allocation over 2 GiB) is kept
# as build-fuzz/fuzz-artifacts/<target>-crash-* and makes the script exit 1.
# Reproduce one with: build-fuzz/csrc/fuzz/<target> FILE
set -eu
repo=$(cd "$(dirname "$0")/.." && pwd)
seconds=${1:-60}
case $seconds in ''|*[!0-9]*) echo "usage: scripts/fuzz.sh [SECONDS]" >&2; exit 2;; esac
# shellcheck source=jobs.sh
. "$repo/scripts/jobs.sh"
jobs_check fuzz.sh
jobs=${JOBS:-2}
build="$repo/build-fuzz"
targets="fuzz_exr_compute fuzz_keep_input fuzz_camera_json"

CC=${FUZZ_CC:-clang} cmake -S "$repo" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DHBAO_BUILD_FUZZERS=ON -DHBAO_BUILD_TOOL=ON -DHBAO_BUILD_TESTS=OFF \
    -DHBAO_BUILD_BENCHMARKS=OFF >/dev/null
# shellcheck disable=SC2086
cmake --build "$build" -j"$jobs" --target $targets >/dev/null

mkdir -p "$build/fuzz-artifacts"

# fuzz TARGET: runs TARGET for its share of SECONDS and writes "STATUS RUNS
# SHARE" to its result file
fuzz() {
    target=$1
    case $target in
        fuzz_camera_json) share=$((seconds * 20 / 100)); dict=json.dict ;;
        *) share=$((seconds * 40 / 100)); dict=exr.dict ;;
    esac
    [ "$share" -ge 1 ] || share=1
    work="$build/fuzz-corpus/$target"
    mkdir -p "$work"
    log="$build/fuzz-$target.log"
    # -close_fd_mask=3: the tool's warnings would flood the log; libFuzzer
    # keeps its own output and the sanitizers' reports on a copy of stderr.
    status=0
    ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=0 \
    UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
        "$build/csrc/fuzz/$target" -max_total_time="$share" -timeout=10 -rss_limit_mb=2048 \
        -malloc_limit_mb=2048 -close_fd_mask=3 -print_final_stats=1 \
        -dict="$repo/csrc/fuzz/$dict" -artifact_prefix="$build/fuzz-artifacts/$target-" \
        "$work" "$repo/csrc/fuzz/corpus/$target" "$repo/tests/fixtures" >"$log" 2>&1 || status=$?
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
    echo "$status ${runs:-0} $share" >"$build/fuzz-$target.result"
}

# Each target is one process on one core, so they run side by side, $JOBS
# (2) at a time, in the order above: on 2 cores the two EXR targets
# together, then the JSON parser. Each still has its share of SECONDS.
running=0
for target in $targets; do
    rm -f "$build/fuzz-$target.result"
    fuzz "$target" &
    running=$((running + 1))
    if [ "$running" -ge "$jobs" ]; then
        wait
        running=0
    fi
done
wait

total=0
findings=0
for target in $targets; do
    log="$build/fuzz-$target.log"
    status=1 runs=0 share=0
    if [ -f "$build/fuzz-$target.result" ]; then
        read -r status runs share <"$build/fuzz-$target.result"
    fi
    total=$((total + runs))
    if [ "$status" -eq 72 ] && grep -q "^==[0-9]*== libFuzzer: run interrupted" "$log"; then
        # libFuzzer's exit status for a SIGINT or SIGTERM (-interrupted_exitcode):
        # the run was stopped, nothing was found (a CI run cancelled in session 65
        # read as a finding); the script still fails
        echo "fuzz.sh: $target: interrupted after $runs executions (a signal); log $log"
        exit 1
    elif [ "$status" -ne 0 ]; then
        findings=$((findings + 1))
        echo "fuzz.sh: $target: FINDING after $runs executions (exit $status); log $log:"
        grep -E "ERROR|SUMMARY|runtime error|fuzz:|Test unit written" "$log" | head -n 20
    else
        echo "fuzz.sh: $target: $runs executions in ${share} s, no finding"
    fi
done
echo "fuzz.sh: $total executions in total, $findings finding(s)"
[ "$findings" -eq 0 ]
