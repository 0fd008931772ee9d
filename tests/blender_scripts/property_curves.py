# SPDX-License-Identifier: GPL-2.0-or-later
"""Run by tests/test_addon.py in each Blender, headless: the HBAO node's
menus and checkbox animated by F-Curves made with the low-level API (no
whole-number flags, linear: values between the keys), and Blur Sharpness by
a muted F-Curve, read by the hook (socket_values.property_value) and by
Blender's own evaluation at frames and subframes between the keys. Prints
MISMATCH lines, then CHECKED {json}: how many values were compared and how
many differed.

  blender -b --addons hbao --python property_curves.py
"""
import json
import os
import sys

import bpy

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))
import blender_scenes  # noqa: E402

compat = sys.modules["hbao.compat"]
socket_values = sys.modules["hbao.socket_values"]
scene = blender_scenes.build_corner_scene(bpy.context.scene, (48, 32), "CYCLES", 1)
node = blender_scenes.hbao_test_tree(scene, os.path.join(bpy.app.tempdir, "unused"))
tree = node.id_data
node.blur_sharpness = 20.0
node.keyframe_insert("blur_sharpness", frame=1)
node.blur_sharpness = 60.0
node.keyframe_insert("blur_sharpness", frame=3)
node.blur_sharpness = 40.0  # what a muted curve leaves
compat.find_fcurve(tree, node.path_from_id("blur_sharpness")).mute = True
action = tree.animation_data.action
for name, (first, last) in (("integration", (0.0, 1.0)), ("half_resolution", (0.0, 1.0)),
                            ("falloff", (0.0, 2.0))):
    path = node.path_from_id(name)
    curve = (action.fcurve_ensure_for_datablock(tree, path)
             if hasattr(action, "fcurve_ensure_for_datablock") else action.fcurves.new(path))
    for frame, value in ((1, first), (3, last)):
        curve.keyframe_points.insert(frame, value).interpolation = "LINEAR"
checked = differed = 0
for frame, subframe in ((1, 0.0), (1, 0.4), (1, 0.6), (2, 0.0), (2, 0.3), (2, 0.9), (3, 0.0)):
    scene.frame_set(frame, subframe=subframe)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = compat.compositor_tree(scene.evaluated_get(depsgraph)).nodes[node.name]
    time = socket_values.animation_time(scene, frame + subframe)
    for name in ("integration", "half_resolution", "falloff", "blur_sharpness"):
        ours = socket_values.property_value(node, name, time, [])
        blenders = getattr(evaluated, name)
        checked += 1
        if ours != blenders:
            differed += 1
            print("MISMATCH", frame + subframe, name, ours, blenders, flush=True)
print("CHECKED", json.dumps({"values": checked, "differed": differed}), flush=True)
