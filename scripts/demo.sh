#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# The demo: renders the demo scene headless with the HBAO compositor node and
# writes out/demo/{without_ao,ao,with_ao,side_by_side}.png. Safe to re-run.
# Uses this checkout's add-on, build/libhbao.so and build/libhbao_exr.so.
# Installs missing Debian packages first (scripts/setup.sh) and (re)builds.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${HBAO_BUILD_DIR:-$REPO/build}"
BLENDER="${BLENDER:-blender}"
OUT="${1:-$REPO/out/demo}"

"$REPO/scripts/setup.sh"
# Incremental: quick when nothing changed, and never a stale library.
cmake -S "$REPO" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$BUILD" -j2 --target hbao hbao_exr

# A private user-scripts folder whose addons/hbao is this checkout's add-on,
# and private preferences beside it (blenders.private_config: Blender given
# none reads the real user's).
USER_SCRIPTS="$(mktemp -d)"
trap 'rm -rf "$USER_SCRIPTS"' EXIT
mkdir -p "$USER_SCRIPTS/addons" "$USER_SCRIPTS/config"
ln -s "$REPO/addon/hbao" "$USER_SCRIPTS/addons/hbao"

mkdir -p "$OUT"
BLENDER_USER_SCRIPTS="$USER_SCRIPTS" BLENDER_USER_CONFIG="$USER_SCRIPTS/config" \
    HBAO_LIBRARY="$BUILD/libhbao.so" \
    HBAO_EXR_LIBRARY="$BUILD/libhbao_exr.so" \
    "$BLENDER" -b --factory-startup -noaudio --addons hbao --python-exit-code 1 \
    --python "$REPO/scripts/demo_render.py" -- "$OUT"
