# SPDX-License-Identifier: GPL-2.0-or-later
"""Run headless in every Blender by tests/test_faults.py: a render in which
a render setting leaves the HBAO node without AO, then that setting put
back without rendering, and the two steps of the add-on's status timer run
as its tick runs them (node_status.drop_fixed_messages, then
render_record.apply_hints: `-b` runs no timer). CASE: compositing,
single_layer or effect (5.3's Enable for Render). Prints RENDERED {json}
and FIXED {json}, the node's [status line, hint line] after each.

  blender -b --addons hbao --python status_fixed.py -- CASE OUT_DIR
"""
import json
import os
import sys

import bpy

case, out_dir = sys.argv[sys.argv.index("--") + 1:][:2]
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import f12_job  # noqa: E402

hbao = sys.modules["hbao"]
scene, node = f12_job.corner_scene_with_node(out_dir)
SETTINGS = {
    "compositing": lambda off: setattr(scene.render, "use_compositing", not off),
    "single_layer": lambda off: setattr(scene.render, "use_single_layer", off),
    "effect": lambda off: setattr(scene.compositor_effects[0], "enable_for_render", not off),
}


def lines(key):
    print(key, json.dumps([node.status, node.hint]), flush=True)


hbao.sync(scene)
SETTINGS[case](True)
bpy.ops.render.render()
lines("RENDERED")
SETTINGS[case](False)
hbao.node_status.drop_fixed_messages()
hbao.render_record.apply_hints()
lines("FIXED")
