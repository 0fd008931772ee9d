#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""What holding the library's memory between F12 renders saves (the
add-on's memory_hold.py): F12 renders in Debian's Blender with a window
(Xvfb), at 1920x1080 unless --size, GAP seconds apart, once with the memory
released after each render (a hold of 0 s, as the add-on did before) and
once held (the add-on's hold). Prints the AO time of each render from the
engine's timing line and the median of all but each run's first (the
first AO of a process pays for its fresh memory either way). With
--recomposite: one F12 render, then RENDERS - 1 changes of the node's Radius
GAP seconds apart with the compositor shown, each re-composited from the
kept passes: the AO time of each change (computed before the helper's
render, recomposite.py) and the medians.

  scripts/bench_memory_hold.py [--renders 8] [--gap 2] [--size 1920x1080] [--rounds 1]
                               [--recomposite]

Rounds alternate which way runs first (released, held; then held,
released; ...).

Needs the build (build/libhbao.so and build/libhbao_exr.so, or the
libraries that HBAO_LIBRARY and HBAO_EXR_LIBRARY name) and Debian's
Blender with xvfb-run (scripts/setup.sh)."""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "scripts"))
sys.path.insert(0, str(REPO / "addon"))
import blenders  # noqa: E402
from hbao import timing_line  # noqa: E402  (bpy-free)

INNER = REPO / "tests" / "blender_scripts" / "ui_memory_hold.py"
# A hold longer than any run here: the memory stays from render to render.
HELD_S = 600.0


def ao_times(blender, user_scripts, out, hold_s, args):
    """The AO milliseconds of each render of one run."""
    env = dict(os.environ, **blenders.user_folders(user_scripts), PYTHONUNBUFFERED="1")
    env.setdefault("HBAO_LIBRARY", str(REPO / "build" / "libhbao.so"))
    env.setdefault("HBAO_EXR_LIBRARY", str(REPO / "build" / "libhbao_exr.so"))
    width, height = args.size
    mode = "recomposite" if args.recomposite else "quit"
    command = blender.command(INNER, [out, hold_s, args.renders, args.gap, width, height, mode],
                              ui=True)
    completed = subprocess.run(command, env=env, stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True, timeout=1800)
    lines = [found for found in map(timing_line.parse, completed.stdout.splitlines())
             if found is not None]
    # A re-composite's AO was computed before the helper's render, which reused it.
    times = [found["kept_ms"] if found["recomposited"] else found["ao_ms"] for found in lines]
    if completed.returncode != 0 or "HOLD: DONE" not in completed.stdout \
            or len(times) != args.renders \
            or sum(found["recomposited"] for found in lines) != (args.renders - 1
                                                                 if args.recomposite else 0) \
            or not all(found["kept_ms"] for found in lines if found["recomposited"]):
        sys.stderr.write(completed.stdout[-3000:])
        raise SystemExit(f"bench_memory_hold: the run with a hold of {hold_s} s failed")
    return times


def _size(text):
    width, _, height = text.partition("x")
    if not (width.isdigit() and height.isdigit() and int(width) > 0 and int(height) > 0):
        raise argparse.ArgumentTypeError(f"{text!r}: give WIDTHxHEIGHT, such as 1920x1080")
    return int(width), int(height)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--renders", type=int, default=8)
    parser.add_argument("--gap", type=float, default=2.0,
                        help="seconds between renders (more than the add-on's 1 s timer)")
    parser.add_argument("--size", type=_size, default=(1920, 1080))
    parser.add_argument("--rounds", type=int, default=1, help="runs of each, alternating")
    parser.add_argument("--recomposite", action="store_true",
                        help="one render, then changes of the Radius, re-composited")
    args = parser.parse_args()
    if args.renders < 2 or args.rounds < 1 or not args.gap >= 0.0:
        raise SystemExit("bench_memory_hold: --renders must be 2 or more, --rounds 1 or more "
                         "and --gap 0 or more")
    blender = blenders.debian_blender()
    if blender is None:
        raise SystemExit("bench_memory_hold: blender not found: run scripts/setup.sh")
    results = {"released after each render": [], "held": []}
    with tempfile.TemporaryDirectory() as folder:
        user_scripts = blenders.user_scripts_with_addon(Path(folder) / "scripts")
        ways = [("released after each render", 0.0), ("held", HELD_S)]
        for round_ in range(args.rounds):
            for name, hold_s in ways if round_ % 2 == 0 else ways[::-1]:
                times = ao_times(blender, user_scripts, Path(folder) / "out", hold_s, args)
                print(f"{name}, run {round_ + 1}: AO ms {times}", flush=True)
                results[name] += times[1:]
    if args.recomposite:
        what = f"an F12 render and {args.renders - 1} changes of the Radius re-composited"
        which = f"changes 1-{args.renders - 1}"
    else:
        what, which = f"{args.renders} F12 renders", f"renders 2-{args.renders}"
    print(f"{blender.name}, {args.size[0]}x{args.size[1]}, {what} a run {args.gap} s apart; "
          f"AO ms of {which}:")
    for name, times in results.items():
        print(f"  {name}: median {statistics.median(times):.0f} "
              f"(min {min(times)}, max {max(times)}, n {len(times)})")


if __name__ == "__main__":
    main()
