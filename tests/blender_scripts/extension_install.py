# SPDX-License-Identifier: GPL-2.0-or-later
"""Run by tests/test_packaging.py in bpy 4.2+: installs the extension zip
that scripts/package_addon.sh built (not the source folder) the way Install
from Disk does, enables it, checks that the installed copy loads its own
native libraries, then renders the test scene of addon_render.py with it.

  python scripts/bpy_blender.py --python extension_install.py -- ZIP SPEC OUT
"""
import os
import runpy
import sys

import bpy

zip_path, spec, out_dir = sys.argv[sys.argv.index("--") + 1:][:3]
MODULE = "bl_ext.user_default.hbao"

bpy.ops.extensions.package_install_files(filepath=zip_path, repo="user_default",
                                         enable_on_install=True)
if MODULE not in bpy.context.preferences.addons:
    sys.exit(f"the extension was not enabled: {list(bpy.context.preferences.addons.keys())}")
installed = sys.modules[MODULE]
native = sys.modules[MODULE + ".native"]
exr_passes = sys.modules[MODULE + ".exr_passes"]
print("INSTALLED", os.path.dirname(installed.__file__))
print("LIBRARY", native.library_path(), native.library_version())
print("EXR LIBRARY", exr_passes.library_path())
exr_passes.load_library()

render_script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "addon_render.py")
sys.argv = [render_script, "--", spec, out_dir]
runpy.run_path(render_script, run_name="__main__")
