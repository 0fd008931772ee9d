# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in a real Blender window (xvfb) by tests/test_faults_ui.py: an F12
render slow enough to interrupt gets a real X key press (xdotool): Escape
(mode "escape") or Ctrl+Z (mode "undo"); then a second, quick F12 render
whose AO is saved.

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
import blender_scenes  # noqa: E402

RENDER_TIMEOUT_S = 240.0
# Escape: samples enough for minutes of Cycles, only Escape ends the first
# render early. Undo: about 10 s of Cycles (4 samples take 0.03 s), which
# ends on its own if the undo does not cancel it.
SLOW_SAMPLES = 1000000 if mode == "escape" else 1500
KEY = {"escape": "Escape", "undo": "ctrl+z"}[mode]
KEY_AFTER_S = 3.0

scene = blender_scenes.build_corner_scene(bpy.context.scene, (96, 64), "CYCLES", SLOW_SAMPLES)
blender_scenes.hbao_test_tree(scene, out_dir)
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


bpy.app.handlers.render_complete.append(on_complete)
bpy.app.handlers.render_cancel.append(on_cancel)


def press_key():
    windows = subprocess.run(["xdotool", "search", "--onlyvisible", "--name", "Blender"],
                             stdout=subprocess.PIPE, text=True).stdout.split()
    for window in windows:
        subprocess.run(["xdotool", "windowfocus", "--sync", window, "key", KEY])
    print("KEY", KEY, "sent to", windows, flush=True)


def step():
    elapsed = time.monotonic() - state["started"]
    if elapsed > RENDER_TIMEOUT_S:
        print("F12: TIMEOUT", state, flush=True)
        bpy.ops.wm.quit_blender()
        return None
    if state["phase"] == "first":
        bpy.ops.render.render("INVOKE_DEFAULT")
        state["phase"], state["first_at"] = "escape", time.monotonic()
    elif state["phase"] == "escape" and time.monotonic() - state["first_at"] > KEY_AFTER_S:
        press_key()
        state["phase"] = "wait_first"
    elif state["phase"] == "wait_first" and state["events"] \
            and not bpy.app.is_job_running("RENDER"):
        print(state["events"][0], "first render", flush=True)
        scene.cycles.samples = 4
        state["events"].clear()
        bpy.ops.render.render("INVOKE_DEFAULT")
        state["phase"] = "second"
    elif state["phase"] == "second" and state["events"] \
            and not bpy.app.is_job_running("RENDER"):
        print("SETTINGS AFTER", settings(), flush=True)
        print("F12: RENDERED", state["events"], flush=True)
        bpy.ops.wm.quit_blender()
        return None
    return 0.25


bpy.app.timers.register(step, first_interval=1.0)
