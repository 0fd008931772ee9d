#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Makes, in dist/:
#   hbao-<version>.zip            the add-on folder hbao/ with lib/libhbao.so,
#                                 lib/libhbao_exr.so and the OpenEXRCore library
#                                 it needs, for Edit > Preferences > Add-ons >
#                                 Install (Blender 3.4-4.1)
#   hbao-<version>-extension.zip  the same files as a Blender 4.2+ extension,
#                                 validated and built by Blender's own extension
#                                 tool (from a bpy that scripts/setup_bpy.sh
#                                 installed), for Install from Disk
# Prints the paths of the zips it made, one a line.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${HBAO_BUILD_DIR:-$REPO/build}"

if [ ! -f "$BUILD/libhbao.so" ] || [ ! -f "$BUILD/libhbao_exr.so" ]; then
    cmake -S "$REPO" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release
    cmake --build "$BUILD" -j2 --target hbao hbao_exr
fi
VERSION="$(sed -n 's/^version = "\(.*\)"/\1/p' "$REPO/addon/hbao/blender_manifest.toml")"
STAGE="$(mktemp -d)"
trap 'rm -rf "$STAGE" "$REPO"/dist/*.partial.$$' EXIT
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
# Each zip is written beside its name and renamed into place: a reader (an
# install, or another packaging run at the same time) sees the old zip or
# the new one, never half of one.
ZIP="$REPO/dist/hbao-$VERSION.zip"
# Each folder has an entry of its own ("hbao/" first): Blender's Install with
# Overwrite removes the folders and files a zip names at its top level, and a
# zip of files alone names none, so it was extracted over the old add-on,
# rewriting the library a running copy has mapped (a crash, SIGBUS).
(cd "$STAGE" && python3 -c '
import sys, zipfile, os
with zipfile.ZipFile(sys.argv[1], "w", zipfile.ZIP_DEFLATED) as archive:
    for root, dirs, files in os.walk("hbao"):
        dirs.sort()
        archive.write(root)
        for name in sorted(files):
            archive.write(os.path.join(root, name))
' "$STAGE/legacy.zip")
mv "$STAGE/legacy.zip" "$ZIP.partial.$$" && mv "$ZIP.partial.$$" "$ZIP"
echo "$ZIP"

# Blender's extension tool runs without Blender; the newest bpy here has it.
if ! TOOL="$(python3 "$REPO/scripts/blenders.py" extension-tool)"; then
    echo "package_addon.sh: no bpy with Blender's extension tool (scripts/setup_bpy.sh);" \
         "the 4.2+ extension zip is not built" >&2
    exit 0
fi
read -r TOOL_PYTHON TOOL_SCRIPT <<<"$TOOL"
"$TOOL_PYTHON" "$TOOL_SCRIPT" validate "$STAGE/hbao" >&2
EXTENSION_ZIP="$REPO/dist/hbao-$VERSION-extension.zip"
"$TOOL_PYTHON" "$TOOL_SCRIPT" build --source-dir "$STAGE/hbao" \
    --output-filepath "$STAGE/extension.zip" >&2
mv "$STAGE/extension.zip" "$EXTENSION_ZIP.partial.$$" && mv "$EXTENSION_ZIP.partial.$$" "$EXTENSION_ZIP"
echo "$EXTENSION_ZIP"
