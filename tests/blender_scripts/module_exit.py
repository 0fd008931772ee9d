# SPDX-License-Identifier: GPL-2.0-or-later
"""Run by tests/test_addon.py with a bpy build's own Python, as a pipeline's
script runs (not through scripts/bpy_blender.py, whose os._exit would hide
how the script ends): bpy 4.5's module hung at exit, after the script's
last line, once the add-on was enabled and a file with an HBAO node open
(compat.NODE_TYPE_HOLDS_MODULE_AT_EXIT).

  python module_exit.py make FILE.blend      the corner scene with an HBAO node
  python module_exit.py render FILE.blend    opens it, renders a frame, ends
  blender -b --python module_exit.py -- STEP FILE.blend   the same in Blender

Prints 'MODULE_EXIT <step> DONE' as its last line."""
import os
import sys

import bpy
import addon_utils  # (in bpy's module, only after bpy)

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))
import blender_scenes  # noqa: E402

# (Blender's application takes the arguments after "--")
step, path = sys.argv[sys.argv.index("--") + 1:][:2] if "--" in sys.argv else sys.argv[1:3]
addon_utils.enable("hbao", default_set=True)
if step == "make":
    scene = blender_scenes.build_corner_scene(resolution=(48, 32), samples=1)
    blender_scenes.hbao_node_tree(scene, "HBAO0")
    bpy.ops.wm.save_as_mainfile(filepath=path)
else:
    bpy.ops.wm.open_mainfile(filepath=path)
    scene = bpy.context.scene
    scene.render.filepath = os.path.join(os.path.dirname(path), "frame")
    bpy.ops.render.render(write_still=True)
print(f"MODULE_EXIT {step} DONE", flush=True)
