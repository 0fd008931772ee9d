# SPDX-License-Identifier: GPL-2.0-or-later
"""Run headless by tests/test_addon.py, in one Blender after another on the
same file: prints the settings (the add-on's node properties) of HBAO node
"HBAO" as 'SETTINGS {json}', making the corner scene with that node where
the file has none; then sets the settings given as JSON ("-": none), and
saves to OUT ("-": no save).

  blender -b [IN.blend] --addons hbao --python older_blender_settings.py -- OUT JSON
"""
import json
import os
import sys

import bpy

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))
import blender_scenes  # noqa: E402

NAMES = ("falloff", "integration", "half_resolution", "blur_sharpness", "guard_band",
         "back_faces")
out, settings = sys.argv[sys.argv.index("--") + 1:][:2]
compat = sys.modules["hbao.compat"]
hbao = next((node for tree in bpy.data.node_groups for node in tree.nodes
             if node.name == "HBAO" and node.bl_idname == "CompositorNodeHBAO"), None)
if hbao is None:
    scene = bpy.context.scene
    tree = compat.compositor_tree(scene)
    hbao = tree.nodes.get("HBAO") if tree is not None else None
if hbao is None:
    scene = blender_scenes.build_corner_scene(bpy.context.scene, (96, 64), "CYCLES", 4)
    _compositor, _layers, hbao = blender_scenes.hbao_node_tree(scene, "HBAO")
else:
    print("SETTINGS " + json.dumps({name: getattr(hbao, name) for name in NAMES}), flush=True)
if settings != "-":
    for name, value in json.loads(settings).items():
        setattr(hbao, name, value)
if out != "-":
    bpy.ops.wm.save_as_mainfile(filepath=out)
