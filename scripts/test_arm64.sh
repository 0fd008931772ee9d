#!/bin/sh
# SPDX-License-Identifier: GPL-2.0-or-later
# The library and its C tests on 64-bit ARM (ARM64 Linux render nodes; the
# CPU of Apple's Macs): cross-built by Debian's gcc-aarch64-linux-gnu
# (cmake/aarch64-linux-gnu.cmake) and run under qemu-user, which ctest starts
# each case through. There the horizon search runs the generic kernel
# (csrc/lib/horizon_generic.c) on Advanced SIMD, and the tests hold it to the
# scalar reference to the bit, on that CPU's instructions.
#
#   scripts/test_arm64.sh [--all]
#
# Under the emulator a case takes some 30 times its native time. Without
# --all the cases in $slow, which took more than 40 s of one core each, are
# left out (about 1200 of the 2050 s that all the cases take, on the 2-core
# Intel Xeon VM of sessions 54-56; the scratch-memory case 247 s since it
# runs each kernel once, 796 before): the native build runs them on every
# kernel this CPU has, the generic one among them. What is left compares
# the generic kernel with the reference on the widest set of settings (the
# four parts of simd_paths_match_scalar_reference, 60-100 s each here, kept
# since session 56: the step's tests took 254 s instead of 106; a quarter
# less since session 62, which stopped running AUTO's kernel twice), planes,
# half depths, back faces, thickness and long thin images. --all runs every
# case (about 17 minutes on 2 cores). Needs what scripts/setup.sh installs
# (the cross compiler, its C library, qemu-user).
set -eu
repo=$(cd "$(dirname "$0")/.." && pwd)
build="$repo/build-arm64"
slow='scratch_memory_is_written_before_it_is_read'
slow="$slow|every_step_and_direction_count_matches_the_scalar_reference|tilted_planes_"
slow="$slow|corner_matches_analytic_hbao|floor_from_eye_height_"
case "${1:-}" in
    --all) exclude='' ;;
    '') exclude=$slow ;;
    *) echo "usage: scripts/test_arm64.sh [--all]" >&2; exit 2 ;;
esac

cmake -S "$repo" -B "$build" -DCMAKE_TOOLCHAIN_FILE="$repo/cmake/aarch64-linux-gnu.cmake" \
    -DCMAKE_BUILD_TYPE=Release -DHBAO_SANITIZE=OFF -DHBAO_BUILD_TOOL=OFF \
    -DHBAO_BUILD_TESTS=ON -DHBAO_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$build" -j"${JOBS:-2}"
if [ -n "$exclude" ]; then
    ctest --test-dir "$build" --output-on-failure --no-tests=error -j"${JOBS:-2}" -E "$exclude"
else
    ctest --test-dir "$build" --output-on-failure --no-tests=error -j"${JOBS:-2}"
fi
