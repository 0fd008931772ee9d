# SPDX-License-Identifier: GPL-2.0-or-later
"""Run headless by tests/test_ui.py: saves a file as the add-on wrote it
before version 2 of the shared group (Directions, Steps and Blur Size as float
sockets), with a value, a Value node link and keyframes on those sockets, and
Radius keyed with a curve's settings and modifiers (OLD RADIUS {frame:
value}), so that opening it with today's add-on shows the upgrade keeps them.

  blender -b --addons hbao --python ui_old_file.py -- OUT.blend
"""
import json
import os
import sys

import bpy

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))
import blender_scenes  # noqa: E402

group_layout = sys.modules["hbao.group_layout"]
# Frames at which the Radius curve is compared before and after an upgrade:
# the keys, between them, the Cycles repeats past them, the Noise range.
RADIUS_FRAMES = (1, 4, 11, 17, 33, 45, 55)
# The version-1 layout: every value socket a float.
group_layout.GROUP_TREE_VERSION = 1
for name, (key, default, low, high, _type, _subtype) in list(group_layout.VALUE_INPUTS.items()):
    group_layout.VALUE_INPUTS[name] = (key, float(default), float(low), float(high),
                                       "NodeSocketFloat", None)

scene = blender_scenes.build_corner_scene(bpy.context.scene, (96, 64), "CYCLES", 4)
compositor, _layers, hbao = blender_scenes.hbao_node_tree(scene, "HBAO")
hbao.inputs["Directions"].default_value = 8.0
# The hidden pass input as layouts 1-4 left it unlinked: 1, the AO of no
# occlusion then.
hbao.inputs[group_layout.AO_PASS_INPUT].default_value = 1.0
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
# Radius keyed with the settings an artist may give a curve (easing, a
# keyframe type, extrapolation, modifiers): an upgrade must keep them all.
radius = hbao.inputs["Radius"]
for frame, size in ((1, 0.5), (11, 0.7)):
    radius.default_value = size
    radius.keyframe_insert("default_value", frame=frame)
curve = sys.modules["hbao.compat"].find_fcurve(hbao.id_data, radius.path_from_id("default_value"))
first, last = curve.keyframe_points
first.interpolation, first.easing, first.back = "BACK", "EASE_OUT", 2.5
last.type = "BREAKDOWN"
curve.extrapolation = "LINEAR"
cycles = curve.modifiers.new("CYCLES")
cycles.mode_after, cycles.cycles_after = "REPEAT_OFFSET", 3
noise = curve.modifiers.new("NOISE")
noise.strength, noise.use_restricted_range = 0.02, True
noise.frame_end, noise.frame_start = 50.0, 40.0
envelope = curve.modifiers.new("ENVELOPE")
envelope.use_restricted_range, envelope.frame_end, envelope.frame_start = True, 58.0, 52.0
envelope.control_points.add(55.0)
# The bounds through foreach_set: a point's own min and max run Blender's
# modifier update with the point as the modifier, which reads past it and
# crashed bpy 5.3 now and then (socket_keys._restore_envelope).
envelope.control_points.foreach_set("min", [0.4])
envelope.control_points.foreach_set("max", [0.9])
# A driver on Thickness: the add-on does not evaluate drivers, but an upgrade
# must not delete the artist's.
driven = hbao.inputs["Thickness"].driver_add("default_value")
driver = driven.driver
driver.type, driver.expression = "SCRIPTED", "0.25 + 0.001 * frame + 0.0 * x"
frame_variable = driver.variables.new()
frame_variable.name = "frame"
frame_variable.targets[0].id_type = "SCENE"
frame_variable.targets[0].id = scene
frame_variable.targets[0].data_path = "frame_current"
x_variable = driver.variables.new()
x_variable.name, x_variable.type = "x", "TRANSFORMS"
x_variable.targets[0].id = scene.camera
x_variable.targets[0].transform_type, x_variable.targets[0].transform_space = \
    "LOC_X", "WORLD_SPACE"
# The driver's curve shaped by hand: keys (0, 0) and (2, 4) alone
while len(driven.keyframe_points):
    driven.keyframe_points.remove(driven.keyframe_points[0])
for frame, value in ((0.0, 0.0), (2.0, 4.0)):
    driven.keyframe_points.insert(frame, value)
# An HBAO node inside an artist's node group: the upgrade keeps its values
# too (it reset Directions to 0 when it looked only at the top level).
artist = bpy.data.node_groups.new("Artist Group", "CompositorNodeTree")
grouped = artist.nodes.new("CompositorNodeHBAO")
grouped.name = "Grouped HBAO"
grouped.inputs["Directions"].default_value = 7.0
holder = compositor.tree.nodes.new("CompositorNodeGroup")
holder.node_tree = artist
holder.location = (hbao.location.x - 600, hbao.location.y - 900)  # beside, off the screenshots
print("OLD DRIVER MODIFIERS", len(driven.modifiers))
print("OLD RADIUS", json.dumps({frame: curve.evaluate(frame) for frame in RADIUS_FRAMES}))
print("OLD SOCKET", hbao.inputs["Directions"].bl_idname)
bpy.ops.wm.save_as_mainfile(filepath=sys.argv[sys.argv.index("--") + 1])
print("SAVED")
