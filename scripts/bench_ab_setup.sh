# SPDX-License-Identifier: GPL-2.0-or-later
# Sourced by bench_ab_copies.sh, bench_ab_pairs.sh and bench_threads.sh, which set REPO first.

# bench_ab_arguments SCRIPT "$@": sets before and after from the first two
# arguments, or prints SCRIPT's usage and exits 2 when they are not files.
bench_ab_arguments() {
    local script=$1
    shift
    if [ $# -lt 2 ] || [ ! -f "$1" ] || [ ! -f "$2" ]; then
        echo "usage: $script BEFORE.so AFTER.so [bench_ab options]" >&2
        exit 2
    fi
    before=$1
    after=$2
}

# bench_ab_count SCRIPT NAME VALUE DIGITS: exits 2 with a message unless
# VALUE (the environment variable NAME's) is a whole number from 1 with at
# most DIGITS digits.
bench_ab_count() {
    local script=$1 name=$2 value=$3 digits=$4
    if ! [[ $value =~ ^[1-9][0-9]{0,$((digits - 1))}$ ]]; then
        echo "$script: $name=$value: give a whole number from 1 to $((10 ** digits - 1))" >&2
        exit 2
    fi
}

# bench_ab_program: sets bench to build/bench_ab, set up and built first
# where it is missing.
bench_ab_program() {
    bench="$REPO/build/bench_ab"
    if [ ! -x "$bench" ]; then
        "$REPO/scripts/setup.sh"
        cmake -S "$REPO" -B "$REPO/build" -DCMAKE_BUILD_TYPE=Release -DHBAO_BUILD_BENCHMARKS=ON \
            >/dev/null
        cmake --build "$REPO/build" -j2 --target bench_ab >/dev/null
    fi
}
