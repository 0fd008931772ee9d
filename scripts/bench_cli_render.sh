#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# The render the CLI benchmarks read: one 1920x1080 frame of the demo scene
# (Debian's Blender, Cycles, 1 sample, 32-bit ZIP multilayer EXR with
# Combined, Depth and Normal), rendered once and kept in .cache/bench/sequence.
# Sets up and builds build/hbao first, then prints the render's path without
# its extension: PATH.exr and PATH.camera.json.
#   scripts/bench_cli_render.sh   (BLENDER=/path/to/blender renders)
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BLENDER="${BLENDER:-blender}"
"$REPO/scripts/setup.sh" >&2
cmake -S "$REPO" -B "$REPO/build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$REPO/build" -j2 --target hbao_tool >/dev/null
CACHE="$REPO/.cache/bench/sequence"
RENDER="$CACHE/demo_1920x1080"
if [ ! -f "$RENDER.exr" ] || [ ! -f "$RENDER.camera.json" ]; then
    mkdir -p "$CACHE"
    "$BLENDER" -b --factory-startup -noaudio --python-exit-code 1 \
        --python "$REPO/scripts/render_passes.py" -- --scene demo --out "$RENDER" \
        --width 1920 --height 1080 --samples 1 --codec ZIP --force >/dev/null
fi
echo "$RENDER"
