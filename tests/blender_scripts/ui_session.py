# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in a real Blender window (xvfb) by tests/test_faults_ui.py: what an
artist does in a session, step by step. Edit > Undo and Redo read the file
back without a depsgraph update; the add-on disabled and enabled in
Preferences.

CASE "delete_undo": F12 (its File Output kept as OUT/first/nodes_0001.exr);
Scene > New, the window back on "Scene", Scene > Delete of it, Ctrl+Z, F12
(kept as OUT/after/nodes_0001.exr). That render had no AO.

CASE "delete_redo": the same to Ctrl+Z, then Ctrl+Shift+Z; prints SCENES
{json} (the window's scene, the scenes) a few seconds later. The window
stayed on the helper scene.

CASE "status_redo": Compositing off, F12 (the node says "Compositing off:
no AO"), Compositing on, F12, Ctrl+Z, Ctrl+Shift+Z; prints STATUS {json}
(the node's status line) a few seconds later. The old line came back.

CASE "pass_turned_on": F12, then the view layer's Normal pass turned off,
which the add-on turns on again for the node; prints TURNED_ON {json}
(status line, hint line) a few seconds later. The status timer wiped the
add-on's "Normal pass turned on" from the line at its next tick.

CASE "reenable": F12 (kept as OUT/first), the add-on disabled and enabled
in Preferences, F12 at once (kept as OUT/after). That render had no AO.

CASE "disable_during": F12 of a render of some seconds, the add-on
disabled in Preferences while it runs (Blender 3.4 crashed), enabled again
once it has ended, F12 (kept as OUT/after).

CASE "failing_refresher": Compositing off, F12 (the node says
"Compositing off: no AO"), a function of the add-on's status poll made to
raise (fault injection: first in hbao.node_status.hint_refreshers, and one that
counts its calls last), Compositing on, F12; prints STATUS {json} and
REFRESHED {json} (whether the last one ran) a few seconds later. Blender
dropped the poll timer at its first error, and the line stayed; then the
poll went on, but stopped at the failing function every tick.

CASE "fixed_causes": three times a render whose status line says why the
node has no AO, then the cause fixed without rendering: Compositing off,
F12, on again; the camera made panoramic, F12, perspective again; Depth
unlinked, F12, linked again; prints STATUS_<CAUSE> {json} (the node's
status line, hint line) after the render and FIXED_<CAUSE> {json} a few
seconds after the fix. The render's line stayed until the next render, and
the hint line said nothing of it but for Depth.

CASE "fixed_after_open": Compositing off, F12, the file saved and opened
again, Compositing on; prints FIXED_OPENED {json} (status line, hint
line) a few seconds later. The line a file kept stayed until a render.

Prints SESSION DONE at the end.

  blender --addons hbao --python ui_session.py -- CASE OUT_DIR
"""
import json
import os
import shutil
import sys
import time

import bpy

case, out_dir = sys.argv[sys.argv.index("--") + 1:][:2]
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import f12_job  # noqa: E402
import timer_guard  # noqa: E402
from ui_areas import node_editor, override  # noqa: E402

TIMEOUT_S = 240.0
SETTLE_S = 3.0

scene = f12_job.corner_scene_with_node(out_dir)[0]
scene.node_tree.nodes["HBAO0"].inputs["Blur Size"].default_value = 0
if case == "disable_during":
    scene.cycles.samples = 4000  # some seconds
job = f12_job.F12Job("SESSION")
started = time.monotonic()


def window():
    return bpy.context.window_manager.windows[0]


def operator(name, **kwargs):
    """An operator in the node editor, as a key press runs it: in the
    window, and a scene operator pushing its undo step."""
    with override(window(), node_editor(window())):
        if name in ("undo", "redo", "undo_push"):
            done = getattr(bpy.ops.ed, name)(**kwargs)
        else:
            done = getattr(bpy.ops.scene, name)("EXEC_DEFAULT", True, **kwargs)
        print(name.upper(), done, flush=True)


def keep(name):
    os.makedirs(os.path.join(out_dir, name), exist_ok=True)
    shutil.copy(os.path.join(out_dir, "nodes_0001.exr"), os.path.join(out_dir, name))


def render():
    job.start()


def rendered():
    return "again" if not job.finished() else 1.0


def compositing(on):
    def step():
        bpy.data.scenes["Scene"].render.use_compositing = on
        operator("undo_push", message=f"compositing {on}")
    return step


def new_scene():
    operator("new", type="NEW")


def back_to_scene():
    window().scene = bpy.data.scenes["Scene"]
    operator("undo_push", message="back to Scene")


def delete():
    operator("delete")
    return SETTLE_S


def built():
    operator("undo_push", message="built")  # (the scene and the hook the sync made)


def undo():
    operator("undo")
    return SETTLE_S


def redo():
    operator("redo")
    return SETTLE_S


def addon(enable):
    def step():
        name = "addon_enable" if enable else "addon_disable"
        print(name.upper(), getattr(bpy.ops.preferences, name)(module="hbao"), flush=True)
    return step


def disable_while_rendering():
    if not bpy.app.is_job_running("RENDER"):
        return "again" if not job.finished() else None  # (ended before: the test says)
    print("DISABLED DURING F12", flush=True)
    addon(False)()
    return 0.1


refreshed = [0]


def failing_refresher():
    def refresh():
        raise RuntimeError("injected")

    def counted():
        refreshed[0] += 1
        return False
    refreshers = sys.modules["hbao"].node_status.hint_refreshers
    refreshers.insert(0, refresh)
    refreshers.append(counted)
    return SETTLE_S


def camera_type(kind):
    def step():
        bpy.data.scenes["Scene"].camera.data.type = kind
        operator("undo_push", message=f"camera {kind}")
    return step


unlinked = []


def depth_link(linked):
    def step():
        tree = bpy.data.scenes["Scene"].node_tree
        depth = tree.nodes["HBAO0"].inputs["Depth"]
        if linked:
            tree.links.new(unlinked.pop(), depth)
        else:
            unlinked.append(depth.links[0].from_socket)
            tree.links.remove(depth.links[0])
        operator("undo_push", message=f"depth linked {linked}")
    return step


def lines():
    node = bpy.data.scenes["Scene"].node_tree.nodes["HBAO0"]
    return [node.status, node.hint]


def fixed(key, cause, fix):
    """A render with `cause`, then `fix`: STATUS_KEY and FIXED_KEY."""
    return [cause, render, rendered, report(f"STATUS_{key}", lines), fix, lambda: SETTLE_S,
            report(f"FIXED_{key}", lines)]


def normal_pass_off():
    bpy.data.scenes["Scene"].view_layers[0].use_pass_normal = False
    operator("undo_push", message="Normal pass off")
    return SETTLE_S


def save_and_open():
    path = os.path.join(out_dir, "saved.blend")
    print("SAVED", bpy.ops.wm.save_as_mainfile(filepath=path), flush=True)
    print("OPENED", bpy.ops.wm.open_mainfile(filepath=path), flush=True)
    return SETTLE_S


def report(key, value):
    def step():
        print(key, json.dumps(value()), flush=True)
    return step


def status():
    return bpy.data.scenes["Scene"].node_tree.nodes["HBAO0"].status


def scenes():
    return {"window": window().scene.name, "scenes": sorted(s.name for s in bpy.data.scenes)}


STEPS = [built] + {
    "delete_undo": [render, rendered, lambda: keep("first"), new_scene, back_to_scene, delete,
                    undo, render, rendered, lambda: keep("after")],
    "delete_redo": [new_scene, back_to_scene, delete, undo, redo, report("SCENES", scenes)],
    "status_redo": [compositing(False), render, rendered, compositing(True), render, rendered,
                    undo, redo, report("STATUS", status)],
    "failing_refresher": [compositing(False), render, rendered, failing_refresher,
                          compositing(True), render, rendered, report("STATUS", status),
                          report("REFRESHED", lambda: refreshed[0] > 0)],
    "fixed_causes": (fixed("COMPOSITING", compositing(False), compositing(True))
                     + fixed("CAMERA", camera_type("PANO"), camera_type("PERSP"))
                     + fixed("DEPTH", depth_link(False), depth_link(True))),
    "fixed_after_open": [compositing(False), render, rendered, save_and_open,
                         report("STATUS_OPENED", lines), compositing(True), lambda: SETTLE_S,
                         report("FIXED_OPENED", lines)],
    "pass_turned_on": [render, rendered, normal_pass_off, report("TURNED_ON", lines)],
    "reenable": [render, rendered, lambda: keep("first"), addon(False), addon(True), render,
                 rendered, lambda: keep("after")],
    "disable_during": [render, disable_while_rendering, rendered, addon(True), render, rendered,
                       lambda: keep("after")],
}[case]
steps = iter(STEPS)
current = [None]


def tick():
    if time.monotonic() - started > TIMEOUT_S:
        timer_guard.give_up("SESSION: TIMEOUT")
    if current[0] is None:
        current[0] = next(steps, None)
        if current[0] is None:
            print("SESSION DONE", flush=True)
            timer_guard.quit_blender()
            return None
    wait = current[0]()
    if wait == "again":
        return 0.1
    current[0] = None
    return 1.0 if wait is None else wait


node_editor(window())
# (persistent: fixed_after_open opens a file)
timer_guard.guarded_timer(tick, SETTLE_S, persistent=True)  # the add-on's sync makes the hook
