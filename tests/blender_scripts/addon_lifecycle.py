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


users_before = scene.users
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

# Nothing points from the helper at the scene: the scene selector shows the
# scene's own users only.
check(scene.users == users_before, f"the scene keeps {users_before} user(s): {scene.users}")
check(helper.get("hbao_main_scene") == scene.name, "the helper keeps the scene's name")
scene.name = "Renamed"
hbao.sync(scene)
check(managed().scene == helper and helper.get("hbao_main_scene") == "Renamed",
      "a renamed scene keeps its helper, which follows the new name")
check(len([s for s in bpy.data.scenes if s.get("hbao_main_scene")]) == 1, "one helper")
# A file saved by an older add-on: the helper held a pointer to the scene.
helper["hbao_main_scene"] = scene
check(scene.users == users_before + 1, "the old pointer counts as a user")
hbao.sync(scene)
check(managed().scene == helper and helper.get("hbao_main_scene") == "Renamed"
      and scene.users == users_before, "sync replaces an old pointer by the name")

tree.nodes.remove(managed())
hbao.sync(scene)
check(managed() is not None and managed().scene == helper
      and len([s for s in bpy.data.scenes if s.get("hbao_main_scene")]) == 1,
      "a managed node deleted by hand comes back, pointing at the same helper")

# The guard band's extra render: made with the setting, before the helper's
# node in the tree (Blender renders them in node order), gone without it.
first.guard_band = 10.0
hbao.sync(scene)
guards = [s for s in bpy.data.scenes if s.get("hbao_guard_for")]
order = [n for n in tree.nodes if n.bl_idname == "CompositorNodeRLayers"]
check(len(guards) == 1 and guards[0].render.engine == "CYCLES"
      and guards[0].camera is not None and abs(guards[0].camera.data.sensor_width
                                               - scene.camera.data.sensor_width * 1.2) < 1e-4,
      "a guard band scene with a camera 1.2x as wide")
guard_node = next(n for n in order if n.get("hbao_guard_node"))
check(order.index(guard_node) < order.index(managed()) and guard_node.scene == guards[0],
      "its Render Layers node comes before the helper's")
for node in (first, second):
    socket = node.inputs["HBAO Pass"]
    check(socket.is_linked and socket.links[0].from_socket.name == f"HBAO {node.pass_index}",
          f"{node.name} is still wired to its pass")
camera_name = guards[0].camera.name
second.back_faces = True
hbao.sync(scene)
backs = [s for s in bpy.data.scenes if s.name.startswith(".HBAO back faces")]
order = [n for n in tree.nodes if n.bl_idname == "CompositorNodeRLayers"]
back_node = next((n for n in order if n.get("hbao_back_node")), None)
check(len(backs) == 1 and backs[0].camera == scene.camera
      and backs[0].view_layers[0].material_override is not None
      and back_node is not None and back_node.scene == backs[0]
      and order.index(back_node) < order.index(managed()),
      "a back faces scene: the scene camera, a material override, its node before the helper's")
second.back_faces = False
first.guard_band = 0.0
hbao.sync(scene)
check(not any(s.name.startswith(".HBAO back faces") for s in bpy.data.scenes)
      and not any(n.get("hbao_back_node") for n in tree.nodes), "the back faces render goes too")
check(not any(s.get("hbao_guard_for") for s in bpy.data.scenes)
      and not any(n.get("hbao_guard_node") for n in tree.nodes)
      and bpy.data.objects.get(camera_name) is None, "all of it goes with the setting")

path = os.path.join(out_dir, "lifecycle.blend")
bpy.ops.wm.save_as_mainfile(filepath=path)
bpy.ops.wm.open_mainfile(filepath=path)
scene = bpy.context.scene
tree = compat.compositor_tree(scene)
hbao.sync(scene)
nodes = [n for n in tree.nodes if n.bl_idname == "CompositorNodeHBAO"]
check(len(nodes) == 2, "both nodes survive save and reload")
check(scene.users == users_before, f"after reload the scene keeps {users_before} user(s)")
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
