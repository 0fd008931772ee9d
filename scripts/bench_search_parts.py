# SPDX-License-Identifier: GPL-2.0-or-later
"""Where a 1080p frame's time goes, part by part of the horizon search:
builds copies of the library with a part of the search taken out (in a
temporary copy of csrc/, never in the working tree), times each against
the library as it is with build/bench_ab (the two builds' calls in
alternating rounds, so both see the machine of the same minutes) and
prints each part's share.

Parts, each the difference between two builds (1 thread unless said):
- the stages around the search: the frame at radius 1e-4 with one pixel
  brought near (bench_ab --near-pixel: without a sampled pixel the library
  computes nothing), where only that pixel's horizons are searched (depth
  conversion, normals, deinterleaving, blur, output; and each block's
  set-up up to its test for active pixels, which then finds none: that
  much of the set-up is counted here);
- the blocks' set-up, the directions' slices and the steps' plans: the
  build without the step loop and without its prefetches, less the stages;
- the plans' prefetches (the memory the steps read): the build without
  the step loop, less the same without the prefetches;
- the step loop (each step's depth load and the test of its height above
  the tangent plane, whether it can raise a horizon): the build whose steps
  stop after that test, less the build without the step loop;
- the rising steps' work (square root, division, horizon update, past the
  normal, the direction's visibility): the library, less the build whose
  steps stop after the test.
The builds without a part give wrong AO (bench_ab says DIFFERENT): they
only time what is left. Only the one-layer search of the SIMD kernels is
taken apart: --back-faces and --implementation scalar are refused.

  python3 scripts/bench_search_parts.py [--rounds 8] [bench_ab options]

bench_ab options (--threads 2, --half, --implementation avx2, --steps 6 ...)
pass through; --radius is the script's own (its stages run sets it).
Needs build/bench_ab: cmake --build build --target bench_ab (a build
configured with -DHBAO_BUILD_BENCHMARKS=ON, the default)."""
import argparse
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from bench_stats import bench_ab_result  # scripts/bench_stats.py, beside this script

REPO = Path(__file__).resolve().parent.parent
BENCH = REPO / "build" / "bench_ab"
KERNEL = "csrc/lib/horizon_simd.h"
PREFETCH_FILES = ("csrc/lib/horizon_avx2.c", "csrc/lib/horizon_avx512.c")

# sample_rising's first test: whether any lane's sample lies above the
# tangent plane (or V below it). A build stops every step right after it.
TANGENT_TEST = "    if (!M_ANY(tangent)) return 0;\n"
# The empty asm keeps the test's branch (and so the load and the height);
# without it the compiler drops the whole step loop, both ways return 0.
STOP_AFTER_TEST = TANGENT_TEST + '    __asm__ volatile("");\n    return 0;\n'
NO_STEP_LOOP = TANGENT_TEST + "    return 0;\n"
PREFETCH_ON = "#define SIMD_PREFETCH_STEPS 1\n"
PREFETCH_OFF = "#define SIMD_PREFETCH_STEPS 0\n"

VARIANTS = {
    "stops_after_test": [(KERNEL, TANGENT_TEST, STOP_AFTER_TEST)],
    "no_step_loop": [(KERNEL, TANGENT_TEST, NO_STEP_LOOP)],
    "no_step_loop_no_prefetch": [(KERNEL, TANGENT_TEST, NO_STEP_LOOP)]
    + [(path, PREFETCH_ON, PREFETCH_OFF) for path in PREFETCH_FILES],
}


def patched_copy(work, name, patches):
    """A copy of the library's sources with `patches` (file, old, new) made,
    each `old` found exactly once; returns the copy's root."""
    root = work / name
    for part in ("CMakeLists.txt", "cmake", "csrc"):
        source = REPO / part
        if source.is_dir():
            shutil.copytree(source, root / part)
        else:
            root.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, root / part)
    for path, old, new in patches:
        text = (root / path).read_text()
        if text.count(old) != 1:
            sys.exit(f"bench_search_parts.py: {path} no longer holds the text this script "
                     f"replaces once ({old.splitlines()[0].strip()!r}): the search changed, "
                     "update the script's patches")
        (root / path).write_text(text.replace(old, new))
    return root


def build_library(root):
    """Builds the copy's libhbao.so (Release, as build/'s) and returns its path."""
    build = root / "build"
    quiet = {"stdout": subprocess.DEVNULL, "check": True}
    subprocess.run(["cmake", "-S", str(root), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
                    "-DHBAO_SANITIZE=OFF", "-DHBAO_BUILD_BENCHMARKS=OFF",
                    "-DHBAO_BUILD_TOOL=OFF", "-DHBAO_BUILD_TESTS=OFF"], **quiet)
    subprocess.run(["cmake", "--build", str(build), "-j2", "--target", "hbao"], **quiet)
    return build / "libhbao.so"


def paired(before, after, rounds, options):
    """bench_ab's fastest time of `before`, what it times (CPU on 1 thread,
    wall on more) and its after / before ratio."""
    out = subprocess.run([str(BENCH), str(before), str(after), "--rounds", str(rounds)]
                         + options, capture_output=True, text=True, check=True).stdout
    found = bench_ab_result(out)
    if found is None:
        sys.exit("bench_search_parts.py: bench_ab printed no result:\n" + out)
    before_ms, _, unit, ratio = found
    return before_ms, unit, ratio


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=8)
    args, options = parser.parse_known_args()
    if args.rounds < 3:
        parser.error("--rounds: at least 3")
    if "--radius" in options:
        parser.error("--radius is the script's own (the stages run sets it)")
    if "--back-faces" in options or any(o in ("scalar", "--implementation=scalar")
                                        for o in options):
        parser.error("only the SIMD kernels' one-layer search is taken apart: "
                     "--back-faces and --implementation scalar would show the whole search "
                     "as set-up")
    if not BENCH.is_file():
        sys.exit("bench_search_parts.py: build/bench_ab is missing: "
                 "cmake --build build --target bench_ab "
                 "(configured with -DHBAO_BUILD_BENCHMARKS=ON)")
    if "--threads" not in options:
        options = options + ["--threads", "1"]
    with tempfile.TemporaryDirectory(prefix="hbao-parts-") as temp:
        work = Path(temp)
        library = build_library(patched_copy(work, "library", []))
        variants = {name: build_library(patched_copy(work, name, patches))
                    for name, patches in VARIANTS.items()}
        fulls, times = [], {}
        for name, path in variants.items():
            full, unit, ratio = paired(library, path, args.rounds, options)
            fulls.append(full)
            times[name] = ratio
        stages, _, _ = paired(library, library, args.rounds,
                              options + ["--radius", "1e-4", "--near-pixel"])
    full = statistics.median(fulls)
    for name in times:
        times[name] *= full
    parts = [
        ("stages around the search (radius 1e-4, one pixel near)", stages),
        ("blocks' set-up, slices and plans", times["no_step_loop_no_prefetch"] - stages),
        ("the plans' prefetches (the steps' memory)",
         times["no_step_loop"] - times["no_step_loop_no_prefetch"]),
        ("step loop: load, height, tangent test",
         times["stops_after_test"] - times["no_step_loop"]),
        ("rising steps' work", full - times["stops_after_test"]),
    ]
    print(f"bench_ab {' '.join(options)}, {args.rounds} rounds a pair; "
          f"the library: {full:.1f} {unit} ms (median of its runs' fastest)")
    print(f"| part | {unit} ms | share |")
    print("|---|---|---|")
    for label, ms in parts:
        print(f"| {label} | {ms:.1f} | {100.0 * ms / full:.0f} % |")
    print(f"| sum | {sum(ms for _, ms in parts):.1f} | |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
