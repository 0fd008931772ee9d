# SPDX-License-Identifier: GPL-2.0-or-later
"""Times the add-on's read of the hand-over's scratch EXR (exr_passes, a view
layer's Depth and Normal) with two builds of libhbao_exr, in alternating
rounds, each in a fresh process so that neither build is loaded twice:

  python3 scripts/bench_exr_read.py BEFORE/libhbao_exr.so AFTER/libhbao_exr.so \\
      FILE.exr [--layer ViewLayer] [--rounds 10] [--reads 7]

FILE.exr: a multilayer EXR as the hand-over saves it (image.save_render,
32-bit, no compression). Prints each build's median read and the median and
quartiles of the rounds' after / before ratios (a round: the median of
--reads reads with each build)."""
import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

import bench_stats

REPO = Path(__file__).resolve().parent.parent

# Run in the child: the reads, timed, with the library HBAO_EXR_LIBRARY names.
CHILD = """
import json, statistics, sys, time
sys.path.insert(0, sys.argv[1])
from hbao import exr_passes
path, layer, reads = sys.argv[2], sys.argv[3], int(sys.argv[4])
groups = {("depth", layer): [layer + ".Depth.Z"],
          ("normal", layer): [layer + ".Normal." + axis for axis in "XYZ"]}
times = []
for _ in range(reads):
    start = time.perf_counter()
    exr_passes.read_channel_groups(path, groups)
    times.append(time.perf_counter() - start)
print(json.dumps(statistics.median(times)))
"""


def median_read(library, args):
    env = dict(os.environ, HBAO_EXR_LIBRARY=str(library))
    completed = subprocess.run(
        [sys.executable, "-c", CHILD, str(REPO / "addon"), str(args.file), args.layer,
         str(args.reads)], env=env, capture_output=True, text=True)
    if completed.returncode != 0:
        last = (completed.stderr.strip().splitlines() or ["(no message)"])[-1]
        raise SystemExit(f"bench_exr_read: reading {args.file} with {library} failed: {last}")
    return json.loads(completed.stdout.strip().splitlines()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before", type=Path)
    parser.add_argument("after", type=Path)
    parser.add_argument("file", type=Path)
    parser.add_argument("--layer", default="ViewLayer")
    parser.add_argument("--rounds", type=int, default=10)
    parser.add_argument("--reads", type=int, default=7)
    args = parser.parse_args()
    for path in (args.before, args.after, args.file):
        if not path.is_file():
            parser.error(f"{path}: no such file")
    if args.rounds < 1 or args.reads < 1:
        parser.error("--rounds and --reads must be at least 1")
    times = {"before": [], "after": []}
    ratios = []
    for round_index in range(args.rounds):
        # each order in turn, so neither build always runs on a warmer machine
        order = ("before", "after") if round_index % 2 == 0 else ("after", "before")
        got = {name: median_read(getattr(args, name), args) for name in order}
        for name in order:
            times[name].append(got[name])
        ratios.append(got["after"] / got["before"])
    size = args.file.stat().st_size / 1e6
    print(f"bench_exr_read: {args.file.name} ({size:.0f} MB), {args.rounds} rounds of "
          f"{args.reads} reads")
    for name in ("before", "after"):
        print(f"  {name}: median {1000 * statistics.median(times[name]):.1f} ms "
              f"({1000 * min(times[name]):.1f}-{1000 * max(times[name]):.1f})")
    print(f"  after / before: {statistics.median(ratios):.3f} "
          f"(quartiles {bench_stats.quartiles(ratios)})")


if __name__ == "__main__":
    main()
