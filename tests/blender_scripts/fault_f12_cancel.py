# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in a real Blender window (xvfb) by tests/test_faults_ui.py: an F12
render slow enough to interrupt gets a real X key press (xdotool): Escape
(mode "escape") or Ctrl+Z (mode "undo") during the main render, or Escape
while the add-on's engine computes the first of two slow HBAO nodes (mode
"escape_in_hbao": a thread watches HBAO_TEMP_DIR, and the press follows the
moment the engine's scratch file of the saved passes is gone); then a
second, quick F12 render whose AO is saved.

  blender --addons hbao --python fault_f12_cancel.py -- <out dir> <mode>

Prints SETTINGS BEFORE/AFTER {json}, CANCELLED or COMPLETED for the first
render, F12: RENDERED after the second; quits."""
import json
import os
import subprocess
import sys
import time

import bpy

out_dir, mode = sys.argv[sys.argv.index("--") + 1:][:2]
REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender_scenes  # noqa: E402
import timer_guard  # noqa: E402

RENDER_TIMEOUT_S = 240.0
# Escape: samples enough for minutes of Cycles, only Escape ends the first
# render early. Undo: about 10 s of Cycles (4 samples take 0.03 s), which
# ends on its own if the undo does not cancel it.
SLOW_SAMPLES = {"escape": 1000000, "undo": 1500, "escape_in_hbao": 4}[mode]
KEY = {"escape": "Escape", "undo": "ctrl+z", "escape_in_hbao": "Escape"}[mode]
KEY_AFTER_S = 3.0
# escape_in_hbao: two nodes of 64 x 64 samples per pixel at 800x480 take
# about a second each on 2 cores; the key goes 0.3 s into the first.
HELPER_KEY_AFTER_S = 0.3

resolution = (800, 480) if mode == "escape_in_hbao" else (96, 64)
scene = blender_scenes.build_corner_scene(bpy.context.scene, resolution, "CYCLES", SLOW_SAMPLES)
first_node = blender_scenes.hbao_test_tree(scene, out_dir)
if mode == "escape_in_hbao":
    tree = first_node.id_data
    layers = next(n for n in tree.nodes if n.bl_idname == "CompositorNodeRLayers")
    second_node = tree.nodes.new("CompositorNodeHBAO")
    second_node.name = "HBAO1"
    for node in (first_node, second_node):
        node.inputs["Directions"].default_value = 64
        node.inputs["Steps"].default_value = 64
        for socket in ("Image", "Depth", "Normal"):
            tree.links.new(layers.outputs[socket], node.inputs[socket])
    viewer = tree.nodes.new("CompositorNodeViewer")
    tree.links.new(second_node.outputs["AO"], viewer.inputs[0])
os.makedirs(out_dir, exist_ok=True)
blender_scenes.compat.set_image_format(scene.render.image_settings, "PNG")


def settings():
    image = scene.render.image_settings
    return json.dumps({"file_format": image.file_format, "color_depth": image.color_depth})


print("SETTINGS BEFORE", settings(), flush=True)
state = {"events": [], "phase": "first", "started": time.monotonic()}


def on_complete(*_args):
    state["events"].append("COMPLETED")


def on_cancel(*_args):
    state["events"].append("CANCELLED")


def watch_scratch():
    """Sets state["helper_at"] when the engine's saved passes have been read
    and deleted: the AO of the first node is being computed then. The file
    lives for milliseconds, hence a thread polling every millisecond."""
    folder = os.environ["HBAO_TEMP_DIR"]
    seen = False
    while "helper_at" not in state and time.monotonic() - state["started"] < RENDER_TIMEOUT_S:
        present = any(name.startswith("hbao-passes-") for name in os.listdir(folder))
        if seen and not present:
            state["helper_at"] = time.monotonic()
        seen = seen or present
        time.sleep(0.001)


bpy.app.handlers.render_complete.append(on_complete)
bpy.app.handlers.render_cancel.append(on_cancel)
if mode == "escape_in_hbao":
    import threading
    threading.Thread(target=watch_scratch, daemon=True).start()


def press_key():
    windows = subprocess.run(["xdotool", "search", "--onlyvisible", "--name", "Blender"],
                             stdout=subprocess.PIPE, text=True).stdout.split()
    for window in windows:
        subprocess.run(["xdotool", "windowfocus", "--sync", window, "key", KEY])
    print("KEY", KEY, "sent to", windows, flush=True)


def step():
    elapsed = time.monotonic() - state["started"]
    if elapsed > RENDER_TIMEOUT_S:
        timer_guard.give_up(f"F12: TIMEOUT {state} (render job running: "
                            f"{bpy.app.is_job_running('RENDER')})")
    if state["phase"] == "first":
        bpy.ops.render.render("INVOKE_DEFAULT")
        state["phase"], state["first_at"] = "escape", time.monotonic()
    elif state["phase"] == "escape" and mode == "escape_in_hbao":
        if "helper_at" in state and time.monotonic() - state["helper_at"] > HELPER_KEY_AFTER_S:
            press_key()
            state["phase"] = "wait_first"
    elif state["phase"] == "escape" and time.monotonic() - state["first_at"] > KEY_AFTER_S:
        press_key()
        state["phase"] = "wait_first"
    elif state["phase"] == "wait_first" and state["events"] \
            and not bpy.app.is_job_running("RENDER"):
        print(state["events"][0], "first render", flush=True)
        scene.cycles.samples = 4
        if mode == "escape_in_hbao":  # the second render: quick, one node of defaults
            tree.nodes.remove(second_node)
            for name in ("Directions", "Steps"):
                first_node.inputs[name].default_value = 4 if name == "Directions" else 16
        state["events"].clear()
        bpy.ops.render.render("INVOKE_DEFAULT")
        state["phase"] = "second"
    elif state["phase"] == "second" and state["events"] \
            and not bpy.app.is_job_running("RENDER"):
        print("SETTINGS AFTER", settings(), flush=True)
        print("F12: RENDERED", state["events"], flush=True)
        timer_guard.quit_blender()
        return None
    return 0.25


timer_guard.guarded_timer(step, 1.0)
