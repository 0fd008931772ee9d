#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# What the render's EXR compression costs a CLI frame: the 1080p render of
# scripts/bench_cli_render.sh, rewritten once in each lossless compression
# that Blender writes (hbao --keep-input: its 8 channels and an AO channel),
# then `hbao IN -o OUT --threads 1` on each, RUNS rounds (default 7), the
# compressions taking turns within a round. Prints each one's file size and
# median CPU seconds (user + system) and wall seconds a frame, fastest and
# slowest round in brackets. The output is ZIP in every case.
#   scripts/bench_cli_codecs.sh [--runs N]   (BLENDER=/path/to/blender renders)
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
RUNS=7
usage() { echo "usage: $0 [--runs N]   (N in [1, 99])" >&2; exit 2; }
while [ $# -gt 0 ]; do
    case "$1" in
        --runs) [ $# -ge 2 ] || usage; RUNS="$2"; shift 2 ;;
        *) usage ;;
    esac
done
case "$RUNS" in ''|*[!0-9]*) usage ;; esac
[ ${#RUNS} -le 2 ] || usage
RUNS=$((10#$RUNS))
[ "$RUNS" -ge 1 ] || usage

RENDER="$("$REPO/scripts/bench_cli_render.sh")"
HBAO="$REPO/build/hbao"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
CODECS="zip zips piz rle none"
for codec in $CODECS; do
    "$HBAO" "$RENDER.exr" -o "$WORK/in_$codec.exr" --keep-input --compression "$codec" \
        --camera "$RENDER.camera.json" 2>/dev/null
done
python3 - "$HBAO" "$WORK" "$RENDER.camera.json" "$RUNS" $CODECS <<'PY'
import os
import statistics
import subprocess
import sys
import time

hbao, work, camera, runs, codecs = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), sys.argv[5:]
cpu = {codec: [] for codec in codecs}
wall = {codec: [] for codec in codecs}
for _ in range(runs):
    for codec in codecs:
        before, start = os.times(), time.perf_counter()
        run = subprocess.run([hbao, os.path.join(work, f"in_{codec}.exr"), "-o",
                              os.path.join(work, "out.exr"), "--camera", camera,
                              "--threads", "1"], capture_output=True, text=True)
        if run.returncode != 0:
            sys.exit(f"hbao failed on the {codec} render (exit {run.returncode}):\n{run.stderr}")
        after = os.times()
        wall[codec].append(time.perf_counter() - start)
        cpu[codec].append(after.children_user + after.children_system
                          - before.children_user - before.children_system)
print(f"hbao on one 1920x1080 frame, 1 thread, median of {runs} rounds (fastest-slowest)")
print("input compression   size MB   CPU s                 wall s")
for codec in codecs:
    size = os.path.getsize(os.path.join(work, f"in_{codec}.exr")) / 1e6
    c, w = cpu[codec], wall[codec]
    print(f"{codec:<19} {size:7.1f}   {statistics.median(c):.2f} ({min(c):.2f}-{max(c):.2f})"
          f"     {statistics.median(w):.2f} ({min(w):.2f}-{max(w):.2f})")
PY
