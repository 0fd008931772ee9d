# SPDX-License-Identifier: GPL-2.0-or-later
"""Run inside Blender by tests/test_addon.py: the add-on disabled and enabled
again in one session, a render after each step. The corner scene with an
HBAO node whose Image feeds the final image (blender_scenes.hbao_test_tree);
each render's final image is written to OUT/<step>.exr (32-bit float):
enabled, muted (the node muted: the plain render), disabled (the add-on
disabled in the session), enabled_again. Prints DISABLED IN SESSION DONE.

  blender -b --addons hbao --python addon_disable_in_session.py -- OUT
"""
import os
import sys

import addon_utils
import bpy

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))
import blender_scenes  # noqa: E402

out_dir = sys.argv[sys.argv.index("--") + 1]
compat = sys.modules["hbao.compat"]
scene = blender_scenes.build_corner_scene(bpy.context.scene, (64, 48), "CYCLES", 4)
node = blender_scenes.hbao_test_tree(scene, os.path.join(out_dir, "nodes"))
settings = scene.render.image_settings
compat.set_image_format(settings, "OPEN_EXR")
settings.color_depth, settings.exr_codec = "32", "NONE"


def render(step):
    scene.render.filepath = os.path.join(out_dir, step)
    bpy.ops.render.render(write_still=True)


render("enabled")
node.mute = True
render("muted")
node.mute = False
addon_utils.disable("hbao", default_set=True)
render("disabled")
addon_utils.enable("hbao", default_set=True)
render("enabled_again")
print("DISABLED IN SESSION DONE", flush=True)
