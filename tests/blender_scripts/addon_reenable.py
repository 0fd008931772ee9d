# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in every Blender of the matrix by tests/test_addon.py: the add-on
disabled and enabled again keeps rendering AO, whether it was disabled by
hand (with an HBAO node in the file) or by Blender loading factory settings
(which disables every add-on, then frees the data), and a file freed after
the add-on was disabled by hand. Each render writes
<out dir>/<stage>/nodes_0001.exr; prints 'STAGE <json>' after each, and
'REENABLE OK' at the end.

  blender -b --addons hbao --python addon_reenable.py -- <out dir>
"""
import json
import os
import sys

import addon_utils
import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "scripts"))
import blender_scenes  # noqa: E402

out_dir = sys.argv[sys.argv.index("--") + 1]


def node_type_registered():
    return bpy.types.Node.bl_rna_get_subclass_py("CompositorNodeHBAO") is not None


def render(stage, build=False):
    scene = bpy.context.scene
    if build:
        blender_scenes.build_corner_scene(scene)
        blender_scenes.hbao_test_tree(scene, os.path.join(out_dir, stage))
    else:  # the same tree, writing elsewhere
        tree = blender_scenes.compat.compositor_tree(scene)
        files = next(n for n in tree.nodes if n.bl_idname == "CompositorNodeOutputFile")
        blender_scenes.file_output.set_path(files, os.path.join(out_dir, stage), "nodes_")
    scene.render.filepath = os.path.join(out_dir, stage, "render_")
    bpy.ops.render.render(write_still=True)
    print("STAGE", json.dumps({"stage": stage, "registered": node_type_registered()}),
          flush=True)


render("enabled", build=True)
addon_utils.disable("hbao", default_set=True)
print("STAGE", json.dumps({"stage": "disabled", "registered": node_type_registered()}),
      flush=True)
if addon_utils.enable("hbao", default_set=True) is None:
    sys.exit("the add-on could not be enabled again")
render("enabled_again")
bpy.ops.wm.read_factory_settings()  # disables every add-on, frees the file
if not addon_utils.check("hbao")[1] and addon_utils.enable("hbao", default_set=True) is None:
    sys.exit("the add-on could not be enabled after loading factory settings")
render("after_factory_settings", build=True)
# Disabled by hand with the node in the file, and the file then freed: the
# type must still be there for the evaluated copies.
addon_utils.disable("hbao", default_set=True)
bpy.ops.wm.read_factory_settings()
print("REENABLE OK", flush=True)
