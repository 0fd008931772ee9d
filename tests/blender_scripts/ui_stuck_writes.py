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
refuses changes then); the artist's edits, done where Blender allows
writes (timer_guard.with_writes_allowed), as the editor's are, which do
not pass through Python: Radius 2 r, and a second HBAO node (HBAO1, Radius
2 r) added, linked to the passes and to a File Output input; ADDED {json}
(whether a write was still refused then); TOLD {json} once the add-on has
said it (within 120 s: how many popups, how long after its node poll
began to ask, the HBAO nodes' line, whether the node poll had redrawn the
nodes for it, whether the node messages it had were shown, and whether
the add-on had linked the new node's AO pass); the Radius set to 2 r
again by a guarded step (EDIT), refused and then run with writes allowed
by timer_guard; F12 (OUT/after), refused, then made with writes allowed
by timer_guard's refused_for_now, as the artist's key is made; RADIUS r,
the artist's edit of the first node's Radius back to r, and 4 s later
HINT "its hint line" (the add-on re-composites from the render's passes
meanwhile: its log line follows);
INFO "text": the Info editor's reports (a render report posted at the
fault among them; a screenshot, OUT/ui_stuck_info.png); STUCK DONE; the
quit (timer_guard's, through with_writes_allowed when refused: the render
may have ended the refusal). From the fault on, the node poll asks for
writes (the last render's messages posted again, and a render report).

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
import file_output  # noqa: E402
from info_editor import info_reports  # noqa: E402
import timer_guard  # noqa: E402

WAIT_S = 20.0  # for the fault's draw and poll
STUCK_REPORT = "a render report posted in the stuck session"
RECOMPOSITE_S = 4.0  # for the add-on's timer (0.25 s) to re-composite
RENDER_WAIT_S = 120.0
scene = f12_job.corner_scene_with_node(out_dir)[0]
node = scene.node_tree.nodes["HBAO0"]
node.inputs["Blur Size"].default_value = 0
radius = node.inputs["Radius"].default_value
job = f12_job.F12Job("STUCK")

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


def still_refused():
    """Whether Blender refuses a write to the scene from Python now."""
    try:
        scene.frame_current = scene.frame_current
        return False
    except AttributeError:
        return True


def edit_and_add_node():
    """What the artist's edits in the node editor do, which Python's
    refusal does not reach: the first node's Radius 2 r; Add > HBAO (its
    init runs where Blender allows writes, as an operator's does), the
    Render Layers' passes linked to it, its Radius and Blur Size set as the
    first node's, its AO given a File Output input. Returns the new node."""
    node.inputs["Radius"].default_value = 2.0 * radius
    tree = scene.node_tree
    added = tree.nodes.new("CompositorNodeHBAO")
    added.name = "HBAO1"
    layers = node.inputs["Depth"].links[0].from_node
    for name in ("Image", "Depth", "Normal"):
        tree.links.new(layers.outputs[name], added.inputs[name])
    added.inputs["Radius"].default_value = 2.0 * radius
    added.inputs["Blur Size"].default_value = 0
    files = next(n for n in tree.nodes if n.bl_idname == "CompositorNodeOutputFile")
    tree.links.new(added.outputs["AO"],
                   file_output.new_input(files, "HBAO1_AO", added.outputs["AO"]))
    return added


def edit_radius():
    """The artist's edit of the first node's Radius back to r."""
    node.inputs["Radius"].default_value = radius


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
    hbao_report = sys.modules["hbao.report"]
    hbao_report.post_last_node_messages()
    hbao_report.post_render_report(STUCK_REPORT)  # (for the Info editor)
    asking = time.monotonic()
    yield 2.0
    writes = sys.modules["hbao.writes"]
    report = {"refused": still_refused(), "told": writes.told_stuck()[0]}
    print(f"STUCK {json.dumps(report)}", flush=True)
    added = timer_guard.with_writes_allowed(edit_and_add_node)
    print(f"ADDED {json.dumps({'refused': still_refused()})}", flush=True)
    ao_pass = added.inputs[sys.modules["hbao.group_layout"].AO_PASS_INPUT]
    waited = time.monotonic()
    while not (writes.told_stuck()[0] and ao_pass.is_linked
               and not hbao_report.has_render_reports()):
        if time.monotonic() - waited > RENDER_WAIT_S:
            break
        yield 0.25
    told, popups = writes.told_stuck()
    after_asking_s = time.monotonic() - asking
    yield 1.0  # (the node poll's next tick redraws the nodes for their line)
    report = {"told": told, "popups": popups, "after_asking_s": after_asking_s,
              "node_line": writes.stuck_line(),
              "line_redrawn": not writes.stuck_line_changed(),
              "messages_shown": not hbao_report.has_node_messages(),
              "added_linked": ao_pass.is_linked}
    print(f"TOLD {json.dumps(report)}", flush=True)
    edited = []

    def edit_again_step():
        # (refused: timer_guard runs the step with writes allowed)
        node.inputs["Radius"].default_value = 2.0 * radius
        edited.append(True)
    timer_guard.guarded_timer(edit_again_step, 0.0, label="EDIT")
    while not edited:
        yield 0.25
    job.start()  # (refused: timer_guard makes it with writes allowed)
    yield from wait_for_render(time.monotonic())
    keep("after")
    print("RADIUS r", flush=True)  # (the log's re-composite line comes after this)
    timer_guard.with_writes_allowed(edit_radius)
    yield RECOMPOSITE_S
    print(f"HINT {json.dumps(node.hint)}", flush=True)
    info = timer_guard.with_writes_allowed(lambda: info_reports(out_dir, "ui_stuck_info.png"))
    print(f"INFO {json.dumps(info)}", flush=True)
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
