# SPDX-License-Identifier: GPL-2.0-or-later
"""Run inside Blender by tests/test_addon.py: the hook's life with the nodes
(no render): created with the first HBAO node, one pass per node, duplicates
get their own pass, synced render settings, kept through save and reload,
removed with the last node. Prints CHECK lines and exits non-zero on failure."""
import os
import sys

import bpy

import hbao
from hbao import compat

out_dir = sys.argv[sys.argv.index("--") + 1]
scene = bpy.context.scene
tree = compat.ensure_compositor_tree(scene)


def check(condition, what):
    print(f"CHECK {'ok' if condition else 'FAILED'}: {what}")
    if not condition:
        sys.exit(1)


def managed():
    return next((n for n in tree.nodes if n.get("hbao_managed")), None)


first = tree.nodes.new("CompositorNodeHBAO")
second = tree.nodes.new("CompositorNodeHBAO")
check(first.pass_index != second.pass_index, "each node gets its own pass")
scene.render.resolution_percentage = 50
scene.render.use_border = True
scene.render.use_crop_to_border = True
hbao.sync(scene)
hook = managed()
check(hook is not None and hook.hide, "a collapsed Render Layers node points at the helper")
helper = hook.scene
check(helper.render.engine == "HBAO_PASSES", "the helper renders with the pass engine")
check(helper.render.resolution_percentage == 50 and helper.render.use_crop_to_border,
      "resolution percentage and crop are synced")
for node in (first, second):
    socket = node.inputs["HBAO Pass"]
    check(socket.is_linked and socket.links[0].from_socket.name == f"HBAO {node.pass_index}",
          f"{node.name} is wired to its pass")

path = os.path.join(out_dir, "lifecycle.blend")
bpy.ops.wm.save_as_mainfile(filepath=path)
bpy.ops.wm.open_mainfile(filepath=path)
scene = bpy.context.scene
tree = compat.compositor_tree(scene)
hbao.sync(scene)
nodes = [n for n in tree.nodes if n.bl_idname == "CompositorNodeHBAO"]
check(len(nodes) == 2, "both nodes survive save and reload")
for node in nodes:
    socket = node.inputs["HBAO Pass"]
    check(socket.is_linked and socket.links[0].from_socket.enabled,
          f"{node.name} is still wired to an available pass after reload")

for node in nodes:
    tree.nodes.remove(node)
hbao.sync(scene)
check(managed() is None, "the Render Layers node goes with the last HBAO node")
check(not any(s.name.startswith(".HBAO passes") for s in bpy.data.scenes),
      "the helper scene goes with the last HBAO node")
print("LIFECYCLE OK")
