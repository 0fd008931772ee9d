# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in a real Blender window (xvfb) by tests/test_faults_ui.py: a
session that Blender leaves refusing Python's writes for good, and the
add-on's F12 in it.

The fault, made on purpose (docs/blender-integration.md, "Rarely the
refusal does not end"): an editor's header's draw (3D view, node or image
editor), in the main thread, waits until a helper thread has entered an
operator's poll, and returns while that poll still runs; the poll returns
last (released by the next timer tick, which runs only once the draw has
returned) and puts back the draw's "refused".

Steps: F12 with Radius 2 r (kept as OUT/reference); Radius r, F12
(OUT/first); the fault, then prints STUCK {json} (whether a write to the
scene was refused 2 s later, and whether the add-on had said Blender
refuses changes then); Radius 2 r and F12, done where Blender allows
writes (timer_guard.with_writes_allowed), as the artist's edit and F12 key
are, which do not pass through Python (OUT/after); TOLD {json} (whether
the add-on said it within 120 s of the render's end, how many popups, how
long after its node poll began to ask, the HBAO nodes' line, and whether
the node poll had redrawn the nodes for it);
STUCK DONE; the quit (timer_guard's, through with_writes_allowed when
refused). From the fault on, the node poll asks for writes (the last
render's messages posted again).

  blender --addons hbao --python ui_stuck_writes.py -- OUT_DIR
"""
import json
import os
import shutil
import sys
import threading
import time

import bpy

out_dir = sys.argv[sys.argv.index("--") + 1]
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import f12_job  # noqa: E402
import timer_guard  # noqa: E402

WAIT_S = 20.0  # for the fault's draw and poll
RENDER_WAIT_S = 120.0
scene = f12_job.corner_scene_with_node(out_dir)[0]
node = scene.node_tree.nodes["HBAO0"]
node.inputs["Blur Size"].default_value = 0
radius = node.inputs["Radius"].default_value
job = f12_job.F12Job()

draw_waits = threading.Event()
draw_entered = threading.Event()
poll_entered = threading.Event()
draw_returned = threading.Event()
poll_may_return = threading.Event()


class TEST_OT_poll_in_thread(bpy.types.Operator):
    """An operator whose poll, called from the helper thread, runs until
    the draw has returned (poll_may_return)."""
    bl_idname = "test.poll_in_thread"
    bl_label = "Poll in a thread"

    @classmethod
    def poll(cls, context):
        if threading.current_thread() is not threading.main_thread():
            poll_entered.set()
            poll_may_return.wait(WAIT_S)
        return True

    def execute(self, context):
        return {"FINISHED"}


def header_draw(_self, _context):
    if draw_waits.is_set() and not draw_entered.is_set():
        draw_entered.set()
        poll_entered.wait(WAIT_S)  # (releases the interpreter's lock)
        draw_returned.set()


def poll_from_thread():
    draw_entered.wait(WAIT_S)
    bpy.ops.test.poll_in_thread.poll()


def edit_and_f12():
    """What the artist's edit and F12 key do, which Python's refusal does
    not reach."""
    node.inputs["Radius"].default_value = 2.0 * radius
    job.ended = False
    return bpy.ops.render.render("INVOKE_DEFAULT")


bpy.utils.register_class(TEST_OT_poll_in_thread)
HEADERS = (bpy.types.VIEW3D_HT_header, bpy.types.NODE_HT_header, bpy.types.IMAGE_HT_header)
for header in HEADERS:
    header.append(header_draw)


def keep(name):
    path = os.path.join(out_dir, "nodes_0001.exr")
    os.makedirs(os.path.join(out_dir, name), exist_ok=True)
    shutil.move(path, os.path.join(out_dir, name))


def redraw_all():
    for window in bpy.context.window_manager.windows:
        for area in window.screen.areas:
            area.tag_redraw()


def wait_for_render(started):
    while not job.finished():
        if time.monotonic() - started > RENDER_WAIT_S:
            timer_guard.give_up("STUCK: the render did not end")
        yield 0.2


def steps():
    for name, value in (("reference", 2.0 * radius), ("first", radius)):
        node.inputs["Radius"].default_value = value
        job.start()
        yield from wait_for_render(time.monotonic())
        keep(name)
    threading.Thread(target=poll_from_thread, daemon=True).start()
    draw_waits.set()
    started = time.monotonic()
    while not draw_returned.is_set():
        if time.monotonic() - started > WAIT_S:
            timer_guard.give_up("STUCK: the header was not drawn")
        redraw_all()
        yield 0.2
    poll_may_return.set()  # (a timer's tick: the draw has returned)
    # the node poll asks for writes from now on (what an HBAO render or an
    # undo leaves it to show)
    sys.modules["hbao.report"].post_last_node_messages()
    asking = time.monotonic()
    yield 2.0
    try:
        scene.frame_current = scene.frame_current
        refused = False
    except AttributeError:
        refused = True
    writes = sys.modules["hbao.writes"]
    told = writes.told_stuck()[0]
    print(f"STUCK {json.dumps({'refused': refused, 'told': told})}", flush=True)
    started = timer_guard.with_writes_allowed(edit_and_f12)
    if started != {"RUNNING_MODAL"}:
        timer_guard.give_up(f"STUCK: F12 gave {started}")
    job.started = True
    yield from wait_for_render(time.monotonic())
    rendered = time.monotonic()
    keep("after")
    while not writes.told_stuck()[0] and time.monotonic() - rendered < RENDER_WAIT_S:
        yield 0.25
    told, popups = writes.told_stuck()
    after_asking_s = time.monotonic() - asking
    yield 1.0  # (the node poll's next tick redraws the nodes for their line)
    report = {"told": told, "popups": popups, "after_asking_s": after_asking_s,
              "node_line": writes.stuck_line(),
              "line_redrawn": not writes.stuck_line_changed()}
    print(f"TOLD {json.dumps(report)}", flush=True)
    print("STUCK DONE", flush=True)
    timer_guard.quit_blender()
    yield None


walker = steps()


def step():
    try:
        return next(walker)
    except StopIteration:
        return None


timer_guard.guarded_timer(step, 1.0)
