# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in a Blender window (xvfb) by tests/test_faults_ui.py: HBAO nodes
shown in the compositor (one linked, with a status line; one unlinked, with
its Connect Passes button), then the add-on disabled from Preferences. The
node type stays registered while a tree holds a node (so the rest of the
compositing runs), and its drawing must not raise at every redraw now that
the add-on's operators are gone (a review found it did). Each step in its
own tick of the event loop, and the window redrawn after the disable.
Prints 'DISABLED NODE: DONE'.

  blender --factory-startup --addons hbao --python ui_disabled_node.py
"""
import os
import sys

import bpy

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender_scenes  # noqa: E402
import timer_guard  # noqa: E402
from ui_areas import node_editor, override  # noqa: E402

state = {"tick": 0}


def tick():
    window = bpy.context.window_manager.windows[0]
    step = state["tick"]
    state["tick"] += 1
    if step == 0:
        scene = blender_scenes.build_corner_scene(bpy.context.scene, (64, 48), "CYCLES", 1)
        linked = blender_scenes.hbao_test_tree(scene, os.path.join(bpy.app.tempdir, "nodes"))
        linked.status, linked.status_details = "Steps clamped to 64", "Steps 100 is above 64"
        unlinked = blender_scenes.Compositor.__new__(blender_scenes.Compositor)
        unlinked.tree = sys.modules["hbao.compat"].compositor_tree(scene)
        unlinked.node("CompositorNodeHBAO", (300, -400)).select = True
        node_editor(window)
    elif step == 1:
        with override(window, node_editor(window)):
            bpy.ops.node.view_all()
    elif step == 2:
        bpy.ops.preferences.addon_disable(module="hbao")
    elif step in (3, 4):
        bpy.ops.wm.redraw_timer(type="DRAW_WIN_SWAP", iterations=1)
    elif step == 5:
        print("DISABLED NODE: DONE", flush=True)
        timer_guard.quit_blender()
        return None
    return 0.3


timer_guard.guarded_timer(tick, 0.5)
