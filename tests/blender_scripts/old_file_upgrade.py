# SPDX-License-Identifier: GPL-2.0-or-later
"""Run inside Blender by tests/test_addon.py on a file that ui_old_file.py
saved (the shared group at version 1, Blur Size keyed 3 at frame 1 and 9 at
frame 11): opening it upgraded the group (load_post). Prints UPGRADE {json}:
the socket types, Directions, where Steps comes from, Blur Size at frames 1,
6 and 11, and the group's version.

  blender -b OLD.blend --addons hbao --python old_file_upgrade.py
"""
import json
import sys

import bpy

compat = sys.modules["hbao.compat"]
node_group = sys.modules["hbao.node_group"]
socket_values = sys.modules["hbao.socket_values"]
tree = compat.compositor_tree(bpy.context.scene)
node = tree.nodes["HBAO"]
blur = node.inputs["Blur Size"]
print("UPGRADE", json.dumps({
    "current": bpy.data.node_groups[node_group.GROUP_TREE_NAME].get(
        node_group.GROUP_VERSION_KEY) == node_group.GROUP_TREE_VERSION,
    "socket_types": {name: node.inputs[name].bl_idname
                     for name in ("Directions", "Steps", "Blur Size")},
    "directions": node.inputs["Directions"].default_value,
    "steps_source": [link.from_node.name for link in node.inputs["Steps"].links],
    "blur": [socket_values.socket_value(tree, blur, float(frame), []) for frame in (1, 6, 11)],
}), flush=True)
