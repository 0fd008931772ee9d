# SPDX-License-Identifier: GPL-2.0-or-later
"""Run by tests/test_addon.py in a Blender without the add-on, on a file
saved with it: makes the file one that the add-on before group layout 5
saved (its pass held the AO: the group multiplied Image by the pass and gave
the pass as AO, 1 where unlinked), and saves it over itself. Prints
OLDER LAYOUT <version>.

  blender -b FILE.blend --factory-startup --python older_layout_file.py
"""
import bpy

GROUP_TREE_NAME = ".HBAO"  # group_layout.py's names (the add-on is not loaded)
VERSION_KEY = "hbao_group_version"
PASS_INPUT = "HBAO Pass"
ONE_MINUS_NODE = "AO = 1 - Pass"

tree = bpy.data.node_groups[GROUP_TREE_NAME]
group_input = next(node for node in tree.nodes if node.bl_idname == "NodeGroupInput")
one_minus = tree.nodes[ONE_MINUS_NODE]
targets = [link.to_socket for link in tree.links if link.from_node == one_minus]
tree.nodes.remove(one_minus)
for target in targets:
    tree.links.new(group_input.outputs[PASS_INPUT], target)
if hasattr(tree, "interface"):
    socket = next(item for item in tree.interface.items_tree
                  if getattr(item, "item_type", "") == "SOCKET" and item.name == PASS_INPUT)
else:
    socket = tree.inputs[PASS_INPUT]
socket.default_value = 1.0
tree[VERSION_KEY] = 4
bpy.ops.wm.save_mainfile()
print("OLDER LAYOUT", tree[VERSION_KEY], flush=True)
