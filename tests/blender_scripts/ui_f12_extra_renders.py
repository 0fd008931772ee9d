# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in a real Blender window (xvfb) by tests/test_ui.py: a node with a
guard band and back faces, set as an artist would (the add-on's timer builds
the extra renders), then an F12 render in the render job's thread. The
add-on's console line names the passes it read ('guard band passes', 'back
faces passes'); the script prints 'F12: DONE' once the job has ended.

With "save", the file is saved while F12 renders: the save starts as the main
scene's render begins and is slow (a save_pre handler after the add-on's
sleeps SAVE_S, as a big file or a pipeline's own handler takes), so the
render reaches the step where Blender renders the add-on's scenes during the
save. It prints

  WRITTEN {scene: [view layer use]}: the add-on's scenes as the save writes them
  RENDERED [scene names]: the scenes Blender rendered for the F12 (frame_change_pre)

  blender --addons hbao --python ui_f12_extra_renders.py -- <out dir> [save]
"""
import json
import os
import sys
import time

import bpy

args = sys.argv[sys.argv.index("--") + 1:]
out_dir, save = args[0], args[1:] == ["save"]
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import f12_job  # noqa: E402
import timer_guard  # noqa: E402

# The add-on syncs from a timer after a setting changes: far less than this.
SYNC_WAIT_S = 1.5
SAVE_S = 3.0
# With "save": enough for the main render to outlast the timer's first look
# (48x32 pixels)
SAVE_SAMPLES = 2000

scene, node = f12_job.corner_scene_with_node(out_dir)
node.guard_band = 10.0
node.back_faces = True
if save:
    scene.cycles.samples = SAVE_SAMPLES
state = {"phase": "sync", "since": time.monotonic(), "save": False}
rendered = []
job = f12_job.F12Job("F12", timeout_s=120.0)


def addon_scenes():
    return {s.name: [layer.use for layer in s.view_layers]
            for s in bpy.data.scenes if s.name.startswith(".HBAO")}


@bpy.app.handlers.persistent
def note_render(render_scene, *_args):
    rendered.append(render_scene.name)


@bpy.app.handlers.persistent
def main_render_starts(render_scene, *_args):
    if render_scene.name == scene.name:
        state["save"] = True


@bpy.app.handlers.persistent
def slow_save(*_args):
    print("WRITTEN " + json.dumps(addon_scenes()), flush=True)
    time.sleep(SAVE_S)


def tick():
    now = time.monotonic()
    if state["phase"] == "sync" and now - state["since"] > SYNC_WAIT_S:
        print("SCENES", sorted(s.name for s in bpy.data.scenes), flush=True)
        if save:
            bpy.app.handlers.frame_change_pre.append(note_render)
            bpy.app.handlers.render_pre.append(main_render_starts)
            bpy.app.handlers.save_pre.append(slow_save)
        state.update(phase="render", since=now)
        job.start()
    elif state["phase"] == "render":
        if state["save"]:
            state["save"] = False
            bpy.ops.wm.save_as_mainfile(filepath=os.path.join(out_dir, "saved.blend"),
                                        copy=True)
        if job.finished():
            print("RENDERED " + json.dumps(sorted(set(rendered))), flush=True)
            print("F12: DONE", flush=True)
            timer_guard.quit_blender()
            return None
    return 0.05


timer_guard.guarded_timer(tick, 0.5)
