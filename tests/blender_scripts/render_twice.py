# SPDX-License-Identifier: GPL-2.0-or-later
"""Run by tests/test_faults.py in each Blender, headless: renders the corner
scene with an HBAO node, then changes one thing and renders again, and
prints what the second render left: 'AFTER {json}' with the node statuses,
the scenes, and whether the second render's output named the helper.

  blender -b --addons hbao --python render_twice.py -- CASE OUT_DIR

CASE: delete_last_node (the only HBAO node deleted between the renders, as a
script does: no timer syncs in `-b`), panoramic_camera (the camera made
panoramic: AO off, which the node must say), guard_band_off and
back_faces_off (the first render with a guard band of 10 %, or with back
faces; the second without: the hook removes that render's scene);
guard_band_off_in_strips (as guard_band_off, the second render a 2-frame
animation of a sequencer scene "Edit" showing the scene in a strip: a job
inside Edit's for each frame).
"""
import json
import os
import sys

import bpy

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))
import blender_scenes  # noqa: E402

case, out_dir = sys.argv[sys.argv.index("--") + 1:][:2]
scene = blender_scenes.build_corner_scene(bpy.context.scene, (48, 32), "CYCLES", 1)
node = blender_scenes.hbao_test_tree(scene, out_dir)
if case in ("guard_band_off", "guard_band_off_in_strips"):
    node.guard_band = 10.0
elif case == "back_faces_off":
    node.back_faces = True
bpy.ops.render.render(write_still=False)
print("FIRST RENDER DONE", flush=True)
if case == "delete_last_node":
    node.id_data.nodes.remove(node)
elif case == "panoramic_camera":
    scene.camera.data.type = "PANO"
elif case in ("guard_band_off", "guard_band_off_in_strips"):
    node.guard_band = 0.0
elif case == "back_faces_off":
    node.back_faces = False
print("SECOND RENDER", flush=True)
if case.endswith("_in_strips"):
    edit = bpy.data.scenes.new("Edit")
    edit.render.resolution_x, edit.render.resolution_y = scene.render.resolution_x, \
        scene.render.resolution_y
    edit.frame_start, edit.frame_end = 1, 2
    editor = edit.sequence_editor_create()
    strips = editor.strips if hasattr(editor, "strips") else editor.sequences
    strips.new_scene("Shot", scene, channel=1, frame_start=1)
    edit.render.filepath = os.path.join(out_dir, "edit_")
    bpy.ops.render.render(animation=True, scene=edit.name)
else:
    bpy.ops.render.render(write_still=False)
node_module = sys.modules["hbao.node"]
sys.modules["hbao.node_status"].apply_node_messages()

statuses = {n.name: n.status for n in node_module.hbao_nodes(
    sys.modules["hbao.compat"].compositor_tree(scene))}
print("AFTER", json.dumps({"statuses": statuses,
                           "scenes": sorted(s.name for s in bpy.data.scenes)}), flush=True)
