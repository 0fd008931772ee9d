# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in a real Blender window (xvfb) by tests/test_ui.py: a node with a
guard band and back faces, set as an artist would (the add-on's timer builds
the extra renders), then an F12 render in the render job's thread. The
add-on's console line names the passes it read ('guard band passes', 'back
faces passes'); the script prints 'F12: DONE' once the job has ended.

  blender --addons hbao --python ui_f12_extra_renders.py -- <out dir>
"""
import os
import sys
import time

import bpy

out_dir = sys.argv[sys.argv.index("--") + 1]
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import f12_job  # noqa: E402
import timer_guard  # noqa: E402

RENDER_TIMEOUT_S = 120.0
# The add-on syncs from a timer after a setting changes: far less than this.
SYNC_WAIT_S = 1.5

scene, node = f12_job.corner_scene_with_node(out_dir)
node.guard_band = 10.0
node.back_faces = True
state = {"phase": "sync", "since": time.monotonic()}
job = f12_job.F12Job()


def tick():
    now = time.monotonic()
    if state["phase"] == "sync" and now - state["since"] > SYNC_WAIT_S:
        print("SCENES", sorted(s.name for s in bpy.data.scenes), flush=True)
        state.update(phase="render", since=now)
        job.start()
    elif state["phase"] == "render":
        if job.finished():
            print("F12: DONE", flush=True)
            timer_guard.quit_blender()
            return None
        if now - state["since"] > RENDER_TIMEOUT_S:
            timer_guard.give_up("F12: TIMEOUT")
    return 0.2


timer_guard.guarded_timer(tick, 0.5)
