# SPDX-License-Identifier: GPL-2.0-or-later
"""Run by tests/test_viewport.py in each Blender: a 3D view's preview
settings with "Use Node Settings" on take the scene's HBAO node values at the
current frame (keyframed Radius, Steps, Thickness, Falloff); off, or with no
node in the scene, they are the view's own. The background depth is the
preview's own either way (viewport/projection.py: BACKGROUND_DEPTH). Prints
'PARAMS <case> <json>'.

  blender -b --addons hbao --python viewport_node_settings.py
"""
import json
import os
import sys

import bpy

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))
import blender_scenes  # noqa: E402

scene = blender_scenes.build_corner_scene(bpy.context.scene, (48, 32), "CYCLES", 1)
node = blender_scenes.hbao_test_tree(scene, os.path.join(bpy.app.tempdir, "unused"))
node.inputs["Steps"].default_value = 7
node.inputs["Thickness"].default_value = 0.2
node.falloff = "QUADRATIC"
radius = node.inputs["Radius"]
for frame, value in ((1, 0.35), (10, 0.9)):
    radius.default_value = value
    radius.keyframe_insert("default_value", frame=frame)
scene.frame_set(10)

screen = bpy.data.screens[0]
view = getattr(screen, "hbao_viewport_views").add()
view.radius = 2.5


def show(case, params):
    keys = ("radius", "steps", "thickness", "falloff", "background_depth")
    print("PARAMS", case, json.dumps({key: params[key] for key in keys}), flush=True)


show("own", view.params(scene))
view.use_node_settings = True
show("node", view.params(scene))
empty = bpy.data.scenes.new("No node")
show("no_node", view.params(empty))
