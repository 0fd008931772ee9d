# SPDX-License-Identifier: GPL-2.0-or-later
"""F12 from a script in a real Blender window (the ui_* scripts): an
INVOKE render runs in the render job's thread, as the F12 key's does; this
tracks when that job has ended. Also the corner test scene with its HBAO
tree, which those scripts render, and show_compositor().

  sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
  import f12_job
"""
import os
import sys
import time

import bpy

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))
import blender_scenes  # noqa: E402  (needs the path above)
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import timer_guard  # noqa: E402


def corner_scene_with_node(out_dir):
    """The small corner scene (48x32, Cycles, 1 sample) and its HBAO node,
    whose File Output writes into out_dir."""
    scene = blender_scenes.build_corner_scene(bpy.context.scene, (48, 32), "CYCLES", 1)
    os.makedirs(out_dir, exist_ok=True)
    return scene, blender_scenes.hbao_test_tree(scene, out_dir)


def show_compositor():
    """The largest area of the first window becomes the compositor's node
    editor: Blender composites again on a change only where one shows the
    tree."""
    area = max(bpy.context.window_manager.windows[0].screen.areas,
               key=lambda a: a.width * a.height)
    area.type = "NODE_EDITOR"
    area.ui_type = "CompositorNodeTree"


# How long a test's F12 render may take before the script gives up.
RENDER_TIMEOUT_S = 240.0


class F12Job:
    """An F12 render a script starts and waits for; one that has not ended
    RENDER_TIMEOUT_S (or timeout_s) after start() ends Blender with
    '<label>: TIMEOUT' (timer_guard.give_up)."""

    def __init__(self, label, timeout_s=RENDER_TIMEOUT_S):
        self.label, self.timeout_s = label, timeout_s
        self.ended, self.started, self.since = False, False, None
        bpy.app.handlers.render_complete.append(self._end)
        bpy.app.handlers.render_cancel.append(self._end)

    def _end(self, *_args):
        self.ended = True

    def start(self):
        """Start the render; where Blender refuses the operator for the
        moment (hbao.writes), finished() asks again."""
        self.ended, self.started, self.since = False, False, time.monotonic()
        self._try_start()

    def _try_start(self):
        self.started = not timer_guard.refused_for_now(
            lambda: bpy.ops.render.render("INVOKE_DEFAULT"), "F12")

    def finished(self):
        """Whether the job started last has ended (its handlers ran and no
        render job runs any more)."""
        if self.since is not None and time.monotonic() - self.since > self.timeout_s:
            timer_guard.give_up(f"{self.label}: TIMEOUT")
        if not self.started:
            self._try_start()
            return False
        return self.ended and not bpy.app.is_job_running("RENDER")
