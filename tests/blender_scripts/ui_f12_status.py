# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in a real Blender window (xvfb) by tests/test_ui.py: three F12-style
renders in the render job thread (render.render('INVOKE_DEFAULT') from a
timer) of a tree whose HBAO node has Depth linked, then unlinked, then linked
again; after each render has ended it waits up to STATUS_WAIT_S for the
node's status line and prints it as 'STATUS <n> <json text>', so the test sees
that the line appears after an F12 render and goes away with the next one.

  blender --addons hbao --python ui_f12_status.py -- <out dir>
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

# The node shows the outcome shortly after the job ends (the add-on polls).
STATUS_WAIT_S = 5.0

scene, node = f12_job.corner_scene_with_node(out_dir)
tree = node.id_data
layers = next(n for n in tree.nodes if n.bl_idname == "CompositorNodeRLayers")

# Per render: what to do to the tree before it.
STEPS = [lambda: None,
         lambda: tree.links.remove(node.inputs["Depth"].links[0]),
         lambda: tree.links.new(layers.outputs["Depth"], node.inputs["Depth"])]
state = {"step": 0, "phase": "start", "since": None}
job = f12_job.F12Job("F12")


def tick():
    now = time.monotonic()
    if state["phase"] == "start":
        if state.get("changed") != state["step"]:  # once, should the step run again
            STEPS[state["step"]]()
            state["changed"] = state["step"]
        state.update(phase="render", since=now)
        print(f"F12: render {state['step']}", flush=True)
        job.start()
    elif state["phase"] == "render":
        if job.finished():
            state.update(phase="status", since=now)
    elif state["phase"] == "status":
        expect_message = state["step"] == 1
        if bool(node.status) != expect_message and now - state["since"] < STATUS_WAIT_S:
            return 0.1
        print(f"STATUS {state['step']} {json.dumps(node.status)}", flush=True)
        state["step"] += 1
        if state["step"] == len(STEPS):
            print("F12: DONE", flush=True)
            timer_guard.quit_blender()
            return None
        state["phase"] = "start"
    return 0.1


timer_guard.guarded_timer(tick, 1.0)
