# SPDX-License-Identifier: GPL-2.0-or-later
"""Run inside Blender by tests/test_addon.py: an HBAO node with its own
values and links on an outdated shared group, whose rebuild Blender refuses
midway (the refusal writes.py knows, raised by the third socket the rebuild
adds), then the rebuild again, as the next sync does. Prints STATE {json}:
the node's values and links after both, and the group's version.

  blender -b --factory-startup --addons hbao --python refused_group_rebuild.py
"""
import json
import os
import sys

import bpy

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))
import blender_scenes  # noqa: E402

node_group = sys.modules["hbao.node_group"]
group_layout = sys.modules["hbao.group_layout"]
scene = blender_scenes.build_corner_scene(bpy.context.scene, (96, 64), "CYCLES", 4)
compositor = blender_scenes.Compositor(scene)
layers = compositor.render_layers()
hbao = compositor.node("CompositorNodeHBAO")
hbao.name = "HBAO"
compositor.link(layers.outputs["Depth"], hbao.inputs["Depth"])
hbao.inputs["Radius"].default_value = 3.5
hbao.inputs["Directions"].default_value = 7
value = compositor.value(0.75)
value.name = "Strength Value"
compositor.link(value.outputs[0], hbao.inputs["Strength"])
tree = bpy.data.node_groups[group_layout.GROUP_TREE_NAME]
tree[group_layout.GROUP_VERSION_KEY] = group_layout.GROUP_TREE_VERSION - 1  # outdated
# Layouts before 5 held the AO in the pass input, 1 where unlinked: kept, it
# would now be full occlusion (a black image wherever the pass is unwritten).
hbao.inputs[group_layout.AO_PASS_INPUT].default_value = 1.0

new_input = group_layout._new_input
calls = [0]


def refused_third(*args, **kwargs):
    calls[0] += 1
    if calls[0] == 3:
        raise AttributeError("Writing to ID classes in this context is not allowed: (test)")
    return new_input(*args, **kwargs)


group_layout._new_input = refused_third
try:
    node_group.upgrade_group_tree()
    refused = False
except AttributeError as error:
    refused = sys.modules["hbao.writes"].writes_refused(error)
group_layout._new_input = new_input
node_group.adopt_group_copies([hbao])  # the next sync: rebuilds, then restores
print("STATE", json.dumps({
    "refused": refused,
    "current": tree.get(group_layout.GROUP_VERSION_KEY) == group_layout.GROUP_TREE_VERSION,
    "radius": hbao.inputs["Radius"].default_value,
    "directions": hbao.inputs["Directions"].default_value,
    "strength_from": [link.from_node.name for link in hbao.inputs["Strength"].links],
    "depth_linked": hbao.inputs["Depth"].is_linked,
    "ao_pass_default": hbao.inputs[group_layout.AO_PASS_INPUT].default_value,
    "pending": node_group.PENDING_KEY in hbao,
}), flush=True)
