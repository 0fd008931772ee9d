#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Regenerates tests/fixtures/: small multilayer EXRs written by Blender itself
# (scripts/render_passes.py), each with its NAME.camera.json. They are
# committed, so tests do not render them; rerun this after changing a scene.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUT="$REPO/tests/fixtures"
BLENDER="${BLENDER:-blender}"
mkdir -p "$OUT"

render() {
    local name="$1"
    shift
    "$BLENDER" -b --factory-startup -noaudio --python-exit-code 1 \
        --python "$REPO/scripts/render_passes.py" -- --out "$OUT/$name" --force \
        --width 64 --height 48 --samples 4 "$@" >/dev/null
    echo "wrote $OUT/$name.exr"
}

render cycles_float_zip --scene demo --codec ZIP --ao-distance 1.0
render cycles_half_piz --scene demo --half --codec PIZ --ao-distance 1.0
render cycles_float_none --scene demo --codec NONE
render cycles_half_b44 --scene demo --half --codec B44
render eevee_half --scene demo --engine BLENDER_EEVEE --half --codec ZIP
render ortho_float --scene demo --ortho --codec ZIP
render two_layers --scene two_layers --codec ZIP
render no_depth --scene demo --no-depth --codec ZIP
blender_version="$("$BLENDER" --version 2>/dev/null | head -n 1)"
cat > "$OUT/README.md" <<README
# Test fixtures

Multilayer OpenEXR files written by ${blender_version} through
\`scripts/render_passes.py\`, 64x48, 4 samples; regenerate with \`scripts/make_fixtures.sh\`.
Each NAME.exr has a NAME.camera.json (Blender's camera properties, the format of
\`hbao --camera\`).

| file | what |
|---|---|
| cycles_float_zip | demo scene, Cycles, 32-bit float, ZIP; Depth, Normal and AO (distance 1) passes |
| cycles_half_piz | the same scene, 16-bit half colour depth, PIZ (Blender keeps Depth/Normal float) |
| cycles_float_none | uncompressed |
| cycles_half_b44 | half float, B44 compression (Blender offers B44 for half only) |
| eevee_half | EEVEE, half float: background depth 65504 |
| ortho_float | orthographic camera |
| two_layers | two view layers with different content |
| no_depth | no Depth pass (the error path) |
README
