# SPDX-License-Identifier: GPL-2.0-or-later
"""Run headless by tests/test_ui.py: saves a file as the add-on wrote it
before version 2 of the shared group (Directions, Steps and Blur Size as float
sockets), with a value, a Value node link and keyframes on those sockets, so
that opening it with today's add-on shows the upgrade keeps them.

  blender -b --addons hbao --python ui_old_file.py -- OUT.blend
"""
import os
import sys

import bpy

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))
import blender_scenes  # noqa: E402

node_group = sys.modules["hbao.node_group"]
# The version-1 layout: every value socket a float.
node_group.GROUP_TREE_VERSION = 1
for name, (key, default, low, high, _type, _subtype) in list(node_group.VALUE_INPUTS.items()):
    node_group.VALUE_INPUTS[name] = (key, float(default), float(low), float(high),
                                     "NodeSocketFloat", None)

scene = blender_scenes.build_corner_scene(bpy.context.scene, (96, 64), "CYCLES", 4)
compositor = blender_scenes.Compositor(scene)
layers = compositor.render_layers()
hbao = compositor.node("CompositorNodeHBAO")
hbao.name = "HBAO"
for name in ("Image", "Depth", "Normal"):
    compositor.link(layers.outputs[name], hbao.inputs[name])
compositor.composite(hbao.outputs["Image"])
hbao.inputs["Directions"].default_value = 8.0
value = compositor.value(7.0)
value.name = "Steps Value"
# Beside the node and below the Render Layers node, over neither: the UI
# test's screenshots show the node.
value.location = (hbao.location.x - 220, hbao.location.y - 470)
compositor.link(value.outputs[0], hbao.inputs["Steps"])
blur = hbao.inputs["Blur Size"]
for frame, size in ((1, 3.0), (11, 9.0)):
    blur.default_value = size
    blur.keyframe_insert("default_value", frame=frame)
print("OLD SOCKET", hbao.inputs["Directions"].bl_idname)
bpy.ops.wm.save_as_mainfile(filepath=sys.argv[sys.argv.index("--") + 1])
print("SAVED")
