# SPDX-License-Identifier: GPL-2.0-or-later
"""F12 from a script in a real Blender window (the ui_* scripts): an
INVOKE render runs in the render job's thread, as the F12 key's does; this
tracks when that job has ended. Also the corner test scene with its HBAO
tree, which those scripts render, and a timer that cannot leave Blender
running without it (guarded_timer).

  sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
  import f12_job
"""
import os
import sys
import traceback

import bpy

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))
import blender_scenes  # noqa: E402  (needs the path above)


def corner_scene_with_node(out_dir):
    """The small corner scene (48x32, Cycles, 1 sample) and its HBAO node,
    whose File Output writes into out_dir."""
    scene = blender_scenes.build_corner_scene(bpy.context.scene, (48, 32), "CYCLES", 1)
    os.makedirs(out_dir, exist_ok=True)
    return scene, blender_scenes.hbao_test_tree(scene, out_dir)


class F12Job:
    def __init__(self):
        self.ended = False
        bpy.app.handlers.render_complete.append(self._end)
        bpy.app.handlers.render_cancel.append(self._end)

    def _end(self, *_args):
        self.ended = True

    def start(self):
        self.ended = False
        bpy.ops.render.render("INVOKE_DEFAULT")

    def finished(self):
        """Whether the job started last has ended (its handlers ran and no
        render job runs any more)."""
        return self.ended and not bpy.app.is_job_running("RENDER")


def give_up(message):
    """Ends Blender at once with exit status 3, after printing message: a
    script's timeout. bpy.ops.wm.quit_blender() only schedules the quit,
    which a render still running can hold up; the test then waited for its
    own timeout and left the process behind."""
    print(message, flush=True)
    os._exit(3)


def guarded_timer(step, first_interval):
    """bpy.app.timers.register(step), except that an exception in step ends
    Blender (exit status 1, the traceback printed) instead of unregistering
    the timer silently and leaving Blender idle until the test's timeout."""
    def guarded():
        try:
            return step()
        except Exception:
            print("SCRIPT ERROR in the timer:", traceback.format_exc(), sep="\n", flush=True)
            os._exit(1)
    bpy.app.timers.register(guarded, first_interval=first_interval)


QUIT_GRACE_S = 30.0


def quit_blender():
    """bpy.ops.wm.quit_blender(), and give_up() if Blender still runs
    QUIT_GRACE_S later: the quit is only scheduled, and a test once waited
    for its 600 s timeout on a Blender left idle (a fresh-clone CI run,
    session 15; not reproduced in 27 runs)."""
    bpy.ops.wm.quit_blender()
    bpy.app.timers.register(lambda: give_up("QUIT: Blender did not end"),
                            first_interval=QUIT_GRACE_S)
