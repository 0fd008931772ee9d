# SPDX-License-Identifier: GPL-2.0-or-later
"""Run headless (`-b`, and the bpy builds) by tests/test_addon.py: one F12
render of the corner scene at WIDTH x HEIGHT with the HBAO node, with a
render_complete handler of this script's before the add-on's and one after
it, each noting the process's resident memory, so that the add-on's release
of the library's memory at the render's end (memory_hold.py) is bracketed
alone. Prints 'RELEASE_B {"before_mb": ..., "after_mb": ..., "held": ...}'.
With "outlived": the add-on's memory_hold unregistered first (as when the
add-on is disabled while an F12 render runs, whose engine outlives it), its
calls of the library's release counted instead: 'RELEASE_B {"releases": how
many came during the render, "held": ...}'.

  blender -b --addons hbao --python memory_release_b.py -- OUT WIDTH HEIGHT [outlived]
"""
import json
import os
import sys

import bpy

arguments = sys.argv[sys.argv.index("--") + 1:]
out_dir, width, height = arguments[0], int(arguments[1]), int(arguments[2])
outlived = arguments[3:] == ["outlived"]
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))), "scripts"))
import blender_scenes  # noqa: E402
from process_memory import status_kib  # noqa: E402

memory_hold = sys.modules["hbao.memory_hold"]
scene = blender_scenes.build_corner_scene(bpy.context.scene, (width, height), "CYCLES", 1)
os.makedirs(out_dir, exist_ok=True)
node = blender_scenes.hbao_test_tree(scene, out_dir)
# At full resolution every buffer the library keeps is a huge-page mapping
# of its own, which the release unmaps (at half resolution the smaller ones
# come from malloc's heap).
assert not node.half_resolution
rss = {}


def before(*_args):
    rss["before_mb"] = status_kib("VmRSS") / 1024


def after(*_args):
    rss["after_mb"] = status_kib("VmRSS") / 1024


if outlived:
    memory_hold.unregister()
    releases = []
    release_memory = memory_hold.native.release_memory

    def counted_release():
        releases.append(1)
        release_memory()

    memory_hold.native.release_memory = counted_release
    bpy.ops.render.render(write_still=False)
    print("RELEASE_B " + json.dumps({"releases": len(releases), "held": memory_hold.held()}),
          flush=True)
    sys.exit(0)
handlers = bpy.app.handlers.render_complete
assert memory_hold._on_render_end in handlers, list(handlers)
handlers.insert(handlers.index(memory_hold._on_render_end), before)
handlers.insert(handlers.index(memory_hold._on_render_end) + 1, after)
bpy.ops.render.render(write_still=False)
print("RELEASE_B " + json.dumps(dict(rss, held=memory_hold.held())), flush=True)
