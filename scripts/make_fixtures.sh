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
# 33 rows: B44's last chunk holds one row, which it cannot make smaller, so it
# is stored uncompressed (OpenEXRCore 3.1 misread such chunks); its twin in ZIP
# holds the same Depth, and Normal to the last float bit (a second render).
render cycles_half_b44_tail --scene demo --half --codec B44 --height 33
render cycles_half_zip_tail --scene demo --half --codec ZIP --height 33
render eevee_half --scene demo --engine BLENDER_EEVEE --half --codec ZIP
render ortho_float --scene demo --ortho --codec ZIP
render two_layers --scene two_layers --codec ZIP
render no_depth --scene demo --no-depth --codec ZIP
# Blender 5's multi-part EXRs need Blender 5, which Debian does not ship: a
# Python with PyPI's bpy 5.x (pip install bpy==5.0.1) renders them.
if [ -n "${BPY5_PYTHON:-}" ]; then
    "$BPY5_PYTHON" "$REPO/scripts/render_blender5_multipart.py" --out "$OUT" >/dev/null
    echo "wrote $OUT/blender5_*.exr"
else
    echo "BPY5_PYTHON not set: kept the Blender 5 multi-part fixtures as they are"
fi
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
| cycles_half_b44_tail | the same, 64x33: the last chunk (one row) stored uncompressed |
| cycles_half_zip_tail | its twin in ZIP: the same Depth, Normal to the last float bit (a second render) |
| eevee_half | EEVEE, half float: background depth 65504 |
| ortho_float | orthographic camera |
| two_layers | two view layers with different content |
| no_depth | no Depth pass (the error path) |

Blender 5 multi-part files, written by Blender 5.0.1 (PyPI's \`bpy\` 5.0.1) through
\`scripts/render_blender5_multipart.py\`, 48x32, 2 samples: one render of a cube on a
floor, saved four ways. \`make_fixtures.sh\` renders them when \`BPY5_PYTHON\` names a
Python that has that \`bpy\`.

| file | what |
|---|---|
| blender5_cycles_multipart | Blender 5's default multilayer layout: 3 parts (Combined, Depth, Normal), 32-bit float, ZIP |
| blender5_cycles_multipart_interleaved | the same pixels in one part (\`use_exr_interleave\`) |
| blender5_half_piz_multipart | the same render, 3 parts, half-float Combined (Depth and Normal stay float), PIZ |
| blender5_half_b44_multipart | the same, B44: the float Depth and Normal parts' chunks stored uncompressed |
README
