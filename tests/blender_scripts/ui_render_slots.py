# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in a real Blender window (xvfb) by tests/test_faults_ui.py: what the
Render Result shows is not the render the add-on handed over.

CASE "switch": F12 into slot 1 (the first render, Radius 1); the cube moved
and F12 into slot 2, and 0.7 s into that render the artist shows slot 1
again (the Image Editor's slot menu). Blender hands over the slot it shows:
the second render got the first one's AO. Its File Output is kept as
OUT/second/nodes_0001.exr, the first's as OUT/first/nodes_0001.exr.

CASE "cancel": F12 (Radius 1) completes; the cube moved, F12 with a million
samples, cancelled with Escape; then Radius 0.3, with the compositor shown.
A refresh applied the first render's AO to the cancelled render. After a
wait, prints HINT {json} (the node's hint line).

CASE "back": F12 into slot 1; the cube moved, F12 into slot 2; slot 1
shown and Radius 0.3 (Blender composites slot 1 with the helper's one
render); slot 2 shown again (BACK TO SLOT 2), Radius 0.31. A refresh then
composited slot 1's image into slot 2. After a wait, prints HINT {json}.

CASE "keep_ui": Render > Display Mode "Keep User Interface"; F12, then
Radius 0.3 with the compositor shown: Blender does not composite the Render
Result again, yet a refresh said it had. After a wait, prints HINT {json}.

Prints SLOTS DONE at the end.

  blender --addons hbao --python ui_render_slots.py -- CASE OUT_DIR
"""
import json
import os
import shutil
import subprocess
import sys
import time

import bpy

case, out_dir = sys.argv[sys.argv.index("--") + 1:][:2]
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import f12_job  # noqa: E402
import timer_guard  # noqa: E402

SETTLE_S = 3.0
# The add-on's timer writes the hint when no render runs: at most this long
HINT_WAIT_S = 20.0

scene, node = f12_job.corner_scene_with_node(out_dir)
node.inputs["Blur Size"].default_value = 0
job = f12_job.F12Job("SLOTS")
state = {"phase": "start", "since": time.monotonic()}


def slots():
    return next(i for i in bpy.data.images if i.type == "RENDER_RESULT").render_slots


def keep(name):
    os.makedirs(os.path.join(out_dir, name), exist_ok=True)
    shutil.copy(os.path.join(out_dir, "nodes_0001.exr"),
                os.path.join(out_dir, name, "nodes_0001.exr"))


def press_escape():
    windows = subprocess.run(["xdotool", "search", "--onlyvisible", "--name", "Blender"],
                             stdout=subprocess.PIPE, text=True).stdout.split()
    for window in windows:
        subprocess.run(["xdotool", "windowfocus", "--sync", window, "key", "Escape"])
    print("ESCAPE sent to", windows, flush=True)


def render(next_phase):
    job.start()
    state.update(phase="rendering", after=next_phase, since=time.monotonic())


def tick():
    now = time.monotonic()
    phase, elapsed = state["phase"], now - state["since"]
    if phase == "rendering":
        if case == "switch" and state["after"] == "second_done" and elapsed > 0.7 \
                and not state.get("switched"):
            slots().active_index = 0
            state["switched"] = True
            print("SWITCHED to slot 1", flush=True)
        if case == "cancel" and state["after"] == "cancelled" and elapsed > 3.0 \
                and not state.get("escaped"):
            press_escape()
            state["escaped"] = True
        if job.finished():
            state.update(phase=state["after"], since=now)
    elif phase == "start":
        f12_job.show_compositor()
        if case == "keep_ui":
            bpy.context.preferences.view.render_display_type = "NONE"
        render("first_done")
    elif phase == "first_done" and elapsed > 1.0:
        keep("first")
        bpy.data.objects["Cube"].location.x += 1.0
        if case == "keep_ui":
            node.inputs["Radius"].default_value = 0.3
            state.update(phase="changed", since=now)
        elif case == "back":
            slots().active_index = 1
            render("second_back")
        elif case == "switch":
            scene.cycles.samples = 3000  # seconds: the switch comes first
            slots().active_index = 1
            render("second_done")
        else:
            scene.cycles.samples = 1000000
            render("cancelled")
    elif phase == "second_back" and elapsed > 1.0:
        slots().active_index = 0
        node.inputs["Radius"].default_value = 0.3
        state.update(phase="older_shown", since=now)
    elif phase == "older_shown" and elapsed > SETTLE_S:
        slots().active_index = 1
        print("BACK TO SLOT 2", flush=True)
        node.inputs["Radius"].default_value = 0.31
        state.update(phase="changed", since=now)
    elif phase == "second_done" and elapsed > 1.0:
        keep("second")
        print("SLOTS DONE", flush=True)
        timer_guard.quit_blender()
        return None
    elif phase == "cancelled" and elapsed > 1.0:
        node.inputs["Radius"].default_value = 0.3
        state.update(phase="changed", since=now)
    elif phase == "changed" and elapsed > SETTLE_S and (node.hint or elapsed > HINT_WAIT_S):
        print(f"HINT {json.dumps(node.hint)}", flush=True)
        print("SLOTS DONE", flush=True)
        timer_guard.quit_blender()
        return None
    return 0.05


timer_guard.guarded_timer(tick, 1.0)
