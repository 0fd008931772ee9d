# SPDX-License-Identifier: GPL-2.0-or-later
"""Run inside Blender by tests/test_addon.py: the add-on disabled and enabled
again in one session, a render after each step. The corner scene with an
HBAO node whose Image feeds the final image (blender_scenes.hbao_test_tree);
each render's final image is written to OUT/<step>.exr (32-bit float):
enabled, muted (the node muted: the plain render), disabled (the add-on
disabled in the session), enabled_again, disabled_under_another (disabled
again after another add-on wrapped Cycles' render over the add-on's
wrapper, engine_wrap.py). Prints ENGINE RENDER {json} (what Cycles'
render() was after each step) and DISABLED IN SESSION DONE.

  blender -b --addons hbao --python addon_disable_in_session.py -- OUT
"""
import functools
import json
import os
import sys

import addon_utils
import bpy
import cycles

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


own_render = cycles.CyclesRender.__dict__["render"]
seen = {}


def note(step):
    """How Cycles' render() stands: its own, the add-on's wrapper of it,
    another's, or a wrapper of a wrapper."""
    render_function = cycles.CyclesRender.__dict__["render"]
    seen[step] = ("own" if render_function is own_render else
                  "another's" if render_function is another_render else
                  "wrapped" if render_function.__module__.endswith(".engine_wrap") else
                  "unknown")


def another_render(self, depsgraph):  # another add-on's wrapper (which
    return wrapped_by_another(self, depsgraph)  # copies the wrapped's attributes)


render("enabled")
note("enabled")
node.mute = True
render("muted")
node.mute = False
addon_utils.disable("hbao", default_set=True)
note("disabled")
render("disabled")
addon_utils.enable("hbao", default_set=True)
render("enabled_again")
note("enabled_again")
wrapped_by_another = cycles.CyclesRender.__dict__["render"]
another_render = functools.wraps(wrapped_by_another)(another_render)
cycles.CyclesRender.render = another_render
addon_utils.disable("hbao", default_set=True)
note("disabled_under_another")
render("disabled_under_another")
print("ENGINE RENDER " + json.dumps(seen), flush=True)
print("DISABLED IN SESSION DONE", flush=True)
