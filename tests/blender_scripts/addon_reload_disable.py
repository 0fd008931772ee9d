# SPDX-License-Identifier: GPL-2.0-or-later
"""Run inside Blender by tests/test_addon.py: the add-on's package reloaded
(what Reload Scripts does to an add-on enabled with --addons), then the
add-on disabled. Prints RELOAD DISABLE {json}: whether each HBAO node's AO
pass is still linked, whether the managed Render Layers node is muted, and
how many of the add-on's handlers are left.

  blender -b --addons hbao --python addon_reload_disable.py -- OUT
"""
import importlib
import json
import os
import sys

import addon_utils
import bpy

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))
import blender_scenes  # noqa: E402

out_dir = sys.argv[sys.argv.index("--") + 1]
scene = blender_scenes.build_corner_scene(bpy.context.scene, (32, 24), "CYCLES", 1)
node = blender_scenes.hbao_test_tree(scene, os.path.join(out_dir, "nodes"))
package = sys.modules["hbao"]
package.sync()
tree = sys.modules["hbao.compat"].compositor_tree(scene)
managed = sys.modules["hbao.helper_lookup"].managed_node(tree)
linked_before = node.inputs["HBAO Pass"].is_linked
importlib.reload(package)
addon_utils.disable("hbao", default_set=True)
watched = (bpy.app.handlers.load_post, bpy.app.handlers.render_pre)
left = [function.__module__ for handlers in watched for function in handlers
        if function.__module__.startswith("hbao")]
print("RELOAD DISABLE", json.dumps({
    "linked_before": linked_before, "linked_after": node.inputs["HBAO Pass"].is_linked,
    "muted": managed.mute, "handlers_left": left}), flush=True)
