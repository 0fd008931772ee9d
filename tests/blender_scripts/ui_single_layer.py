# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in a real Blender window (xvfb) by tests/test_ui.py: Render Single
Layer switched on and off as an artist does, between F12 renders. With it on
Blender renders no other scene, the HBAO helper neither, so the add-on must
unlink the node from the helper's pass before the F12 job starts (its
thread may not edit the tree): prints 'LINKED <when> <bool>' for the node's
HBAO Pass input after each switch has settled, 'STATUS <json>' after the
render, and 'SINGLE LAYER: DONE'.

  blender --addons hbao --python ui_single_layer.py -- <out dir>
"""
import json
import os
import sys
import time

import bpy

out_dir = sys.argv[sys.argv.index("--") + 1]
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import f12_job  # noqa: E402
import timer_guard  # noqa: E402

# The add-on syncs from a timer: give it this long to follow a switch.
SETTLE_S = 5.0

scene, node = f12_job.corner_scene_with_node(out_dir)
ao_pass = node.inputs[sys.modules["hbao.node"].AO_PASS_INPUT]
job = f12_job.F12Job("SINGLE LAYER")
state = {"phase": "before", "since": time.monotonic()}


def settled(linked_wanted, when, then):
    """Wait (up to SETTLE_S) for the link to be as wanted, print it, go on."""
    now = time.monotonic()
    if ao_pass.is_linked != linked_wanted and now - state["since"] < SETTLE_S:
        return
    print(f"LINKED {when} {ao_pass.is_linked}", flush=True)
    state.update(phase=then, since=now)


def tick():
    phase = state["phase"]
    if phase == "before":
        settled(True, "before", "switch_on")
    elif phase == "switch_on":
        scene.render.use_single_layer = True
        state.update(phase="on", since=time.monotonic())
    elif phase == "on":
        settled(False, "on", "render")
    elif phase == "render":
        job.start()
        state.update(phase="rendering", since=time.monotonic())
    elif phase == "rendering":
        if job.finished():
            state.update(phase="status", since=time.monotonic())
    elif phase == "status":
        if not node.status and time.monotonic() - state["since"] < SETTLE_S:
            return 0.1
        print(f"STATUS {json.dumps(node.status)}", flush=True)
        scene.render.use_single_layer = False
        state.update(phase="off", since=time.monotonic())
    elif phase == "off":
        settled(True, "off", "done")
    else:
        print("SINGLE LAYER: DONE", flush=True)
        timer_guard.quit_blender()
        return None
    return 0.1


timer_guard.guarded_timer(tick, 1.0)
