#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Makes dist/hbao-<version>.zip: the add-on folder hbao/ with lib/libhbao.so,
# lib/libhbao_exr.so and the OpenEXRCore library it needs inside, for Edit >
# Preferences > Add-ons > Install (3.x-4.1) or Install from Disk (4.2+
# extensions, via blender_manifest.toml).
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${HBAO_BUILD_DIR:-$REPO/build}"

if [ ! -f "$BUILD/libhbao.so" ] || [ ! -f "$BUILD/libhbao_exr.so" ]; then
    cmake -S "$REPO" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release
    cmake --build "$BUILD" -j2 --target hbao hbao_exr
fi
VERSION="$(sed -n 's/^version = "\(.*\)"/\1/p' "$REPO/addon/hbao/blender_manifest.toml")"
STAGE="$(mktemp -d)"
trap 'rm -rf "$STAGE"' EXIT
# shellcheck source=addon_files.sh
. "$REPO/scripts/addon_files.sh"
mkdir -p "$REPO/dist"
copy_addon "$STAGE/hbao" "$BUILD"
# Official Blender builds link OpenEXR statically and install no shared
# copy: ship the OpenEXRCore that libhbao_exr.so was linked against next to
# it (its RUNPATH is $ORIGIN), with its licence.
OPENEXR_CORE="$(ldd "$BUILD/libhbao_exr.so" | awk '/libOpenEXRCore/ { print $3 }')"
if [ -z "$OPENEXR_CORE" ] || [ ! -f "$OPENEXR_CORE" ]; then
    echo "package_addon.sh: cannot find the OpenEXRCore library libhbao_exr.so uses" >&2
    exit 1
fi
cp "$OPENEXR_CORE" "$STAGE/hbao/lib/$(basename "$OPENEXR_CORE")"
for licence in /usr/share/doc/libopenexr*/copyright; do
    if [ -f "$licence" ]; then
        cp "$licence" "$STAGE/hbao/lib/OpenEXR-COPYRIGHT"
        break
    fi
done
ZIP="$REPO/dist/hbao-$VERSION.zip"
rm -f "$ZIP"
(cd "$STAGE" && python3 -c '
import sys, zipfile, os
with zipfile.ZipFile(sys.argv[1], "w", zipfile.ZIP_DEFLATED) as archive:
    for root, _dirs, files in os.walk("hbao"):
        for name in sorted(files):
            archive.write(os.path.join(root, name))
' "$ZIP")
echo "$ZIP"
