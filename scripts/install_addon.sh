#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Builds libhbao and libhbao_exr if needed, copies the add-on (with
# lib/libhbao.so and lib/libhbao_exr.so) into the current user's Blender
# add-ons folder, enables it and saves the preferences.
#   scripts/install_addon.sh            (BLENDER=/path/to/blender to choose one)
# With BLENDER_USER_SCRIPTS set (an add-ons folder of your choosing), the
# preferences go beside it, to $BLENDER_USER_SCRIPTS/config, unless
# BLENDER_USER_CONFIG says where: never into the real user's preferences.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if [ -n "${BLENDER_USER_SCRIPTS:-}" ] && [ -z "${BLENDER_USER_CONFIG:-}" ]; then
    export BLENDER_USER_CONFIG="$BLENDER_USER_SCRIPTS/config"
fi
# Made first: where BLENDER_USER_CONFIG is missing, Blender quietly saves
# into the real user's config folder instead, if that one exists.
if [ -n "${BLENDER_USER_CONFIG:-}" ]; then
    mkdir -p "$BLENDER_USER_CONFIG"
fi
BUILD="${HBAO_BUILD_DIR:-$REPO/build}"
BLENDER="${BLENDER:-blender}"
# shellcheck source=addon_files.sh
. "$REPO/scripts/addon_files.sh"

if [ ! -f "$BUILD/libhbao.so" ] || [ ! -f "$BUILD/libhbao_exr.so" ]; then
    cmake -S "$REPO" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release
    cmake --build "$BUILD" -j2 --target hbao hbao_exr
fi

# Blender's own idea of the user add-ons folder (honours BLENDER_USER_SCRIPTS).
ADDONS_DIR="$("$BLENDER" -b --factory-startup --python-expr \
    'import bpy; print("ADDONS_DIR=" + bpy.utils.user_resource("SCRIPTS", path="addons", create=True))' \
    2>/dev/null | sed -n 's/^ADDONS_DIR=//p')"
if [ -z "$ADDONS_DIR" ]; then
    echo "install_addon.sh: could not ask $BLENDER for its add-ons folder" >&2
    exit 1
fi

TARGET="$ADDONS_DIR/hbao"
rm -rf "$TARGET"
# The package (the viewport subpackage too) and its libraries.
copy_addon "$TARGET" "$BUILD"

"$BLENDER" -b --python-expr '
import addon_utils, bpy, sys
addon_utils.enable("hbao", default_set=True, persistent=True, handle_error=None)
if "hbao" not in bpy.context.preferences.addons:
    sys.exit("install_addon.sh: Blender could not enable the hbao add-on")
bpy.ops.wm.save_userpref()
print("HBAO add-on enabled and preferences saved")
' --python-exit-code 1
echo "Installed to $TARGET"
