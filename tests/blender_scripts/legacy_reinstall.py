# SPDX-License-Identifier: GPL-2.0-or-later
"""Run by tests/test_packaging.py: installs the legacy zip the way
Preferences > Add-ons > Install does, enables it and renders the test scene
of addon_render.py; then installs a second zip over the enabled add-on
(Install with Overwrite, as an artist updating it does) and renders again.
Blender keeps the first copy's modules and native library loaded, so the
second install must not write over the files they came from.

  blender -b --python legacy_reinstall.py -- FIRST_ZIP SECOND_ZIP SPEC OUT
"""
import os
import runpy
import sys

import addon_utils
import bpy

first, second, spec, out_dir = sys.argv[sys.argv.index("--") + 1:][:4]
RENDER_SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "addon_render.py")


def render(name):
    sys.argv = [RENDER_SCRIPT, "--", spec, os.path.join(out_dir, name)]
    runpy.run_path(RENDER_SCRIPT, run_name="__main__")


bpy.ops.preferences.addon_install(filepath=first, overwrite=True)
addon_utils.enable("hbao", default_set=True)
print("LIBRARY", sys.modules["hbao.native"].library_path(), flush=True)
render("first")
bpy.ops.preferences.addon_install(filepath=second, overwrite=True)
print("INSTALLED OVER", flush=True)
render("second")
print("REINSTALLED")
