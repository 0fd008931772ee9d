# SPDX-License-Identifier: GPL-2.0-or-later
"""Run inside Blender by tests/test_addon.py: a file whose scene has an HBAO
node (so it has the add-on's group) appends the scene of BLEND, which has one
too (its own copy of the group, perhaps an older layout: ui_old_file.py),
saves the file (as an artist would: the add-on tidies the groups there and
in the UI's timer, not in a `-b` script's render) and renders the appended
scene. Usage:

  blender -b --factory-startup --addons hbao --python addon_append_groups.py -- BLEND OUT

Prints GROUPS {json}: the node groups named like the add-on's, the group each
HBAO node uses, the appended node's socket types and values (frame 1 and
11), where its Steps comes from, and whether it rendered with AO."""
import json
import os
import sys

import bpy

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))
import blender_scenes  # noqa: E402

compat = sys.modules["hbao.compat"]
socket_values = sys.modules["hbao.socket_values"]
blend, out_dir = sys.argv[sys.argv.index("--") + 1:][:2]
local = blender_scenes.build_corner_scene(bpy.context.scene, (96, 64), "CYCLES", 4)
local.name = "Local"
blender_scenes.Compositor(local).node("CompositorNodeHBAO").name = "Local HBAO"
with bpy.data.libraries.load(blend) as (data_from, data_to):
    data_to.scenes = [name for name in data_from.scenes if not name.startswith(".HBAO")]
scene = data_to.scenes[0]
bpy.ops.wm.save_as_mainfile(filepath=os.path.join(out_dir, "appended.blend"))
scene.render.filepath = os.path.join(out_dir, "frame")
bpy.ops.render.render(write_still=True, scene=scene.name)
tree = compat.compositor_tree(scene)
node = tree.nodes["HBAO"]


def at(frame, name):
    return socket_values.socket_value(node.inputs[name], float(frame), [])


report = {
    "groups": sorted(g.name for g in bpy.data.node_groups if g.name.startswith(".HBAO")),
    "used": sorted({n.node_tree.name for s in bpy.data.scenes
                    for n in getattr(compat.compositor_tree(s), "nodes", ())
                    if n.bl_idname == "CompositorNodeHBAO"}),
    "socket_types": {name: node.inputs[name].bl_idname
                     for name in ("Directions", "Steps", "Blur Size")},
    "directions": node.inputs["Directions"].default_value,
    "steps_source": [link.from_node.name for link in node.inputs["Steps"].links],
    "depth_linked": node.inputs["Depth"].is_linked,
    "blur_at_1": at(1, "Blur Size"), "blur_at_11": at(11, "Blur Size"),
    "status": node.status,
    "ao_pass_value": node.inputs[sys.modules["hbao.group_layout"].AO_PASS_INPUT].default_value,
}
print("GROUPS", json.dumps(report), flush=True)
