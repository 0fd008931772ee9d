# SPDX-License-Identifier: GPL-2.0-or-later
"""Run inside Blender by tests/test_addon.py: brings the scene of a saved
.blend that has an HBAO node into a new file, appended or linked, and renders
it. Usage:

  blender -b --factory-startup --addons hbao --python addon_append.py -- BLEND append|link OUT

An appended scene is local: it renders to OUT/frame_0001.exr. A linked one is
read-only: it renders as saved. Either way the blend's File Output node writes
the node's outputs where the blend says (nodes_0001.exr). Prints
APPEND_RENDERED <scene name>."""
import os
import sys

import bpy

blend, how, out_dir = sys.argv[sys.argv.index("--") + 1:][:3]
# The new file's own scene is called "Scene" too: rename it, so that the render
# operator's scene name means the brought scene.
bpy.context.scene.name = "Local"
with bpy.data.libraries.load(blend, link=(how == "link")) as (data_from, data_to):
    data_to.scenes = [name for name in data_from.scenes if not name.startswith(".HBAO")]
scene = data_to.scenes[0]
if how == "append":
    scene.render.filepath = os.path.join(out_dir, "frame_0001")
# The new file's own scene stays the current one; render the brought one.
scene.frame_set(1)
bpy.ops.render.render(write_still=(how == "append"), scene=scene.name)
print("APPEND_RENDERED", scene.name, flush=True)
