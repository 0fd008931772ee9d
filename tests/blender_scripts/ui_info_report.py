# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in a real Blender window (xvfb) by tests/test_ui.py: an F12-style
render (the render job's thread) of a tree whose HBAO node has Depth
unlinked; once it has ended, one area of the window becomes the Info editor,
its reports are copied (info.select_all + info.report_copy, what Ctrl+C does
there) and read from the clipboard, and printed as 'INFO <json text>'; a
screenshot of the window shows the Info editor. A report posted as the
render ends meets a tick of the add-on's timer where Blender refuses
operators (writes_refused.py) first.

  blender --addons hbao --python ui_info_report.py -- <out dir> <shot dir>
"""
import json
import os
import sys
import time

import bpy

out_dir, shot_dir = sys.argv[sys.argv.index("--") + 1:][:2]
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import f12_job  # noqa: E402
import timer_guard  # noqa: E402
from info_editor import info_reports  # noqa: E402
from writes_refused import while_writes_refused  # noqa: E402

from hbao import render_reports, report  # noqa: E402

SETTLE_S = 1.0
REFUSED_REPORT = "posted before a tick where Blender refused operators"

scene, node = f12_job.corner_scene_with_node(out_dir)
node.id_data.links.remove(node.inputs["Depth"].links[0])
state = {"phase": "start", "since": time.monotonic()}
job = f12_job.F12Job("INFO")


def tick():
    now = time.monotonic()
    if state["phase"] == "start":
        state.update(phase="render", since=now)
        job.start()
    elif state["phase"] == "render":
        if job.finished():
            # A tick of the add-on's reports timer where Blender refuses
            # operators (another thread drawing or rendering): the report
            # waits for a later tick instead of being dropped.
            report.post_render_report(REFUSED_REPORT)
            while_writes_refused(render_reports._poll)
            print("INFO: PENDING AFTER A REFUSED TICK", report.has_render_reports(), flush=True)
            state.update(phase="settle", since=now)
    elif state["phase"] == "settle" and now - state["since"] > SETTLE_S:
        print(f"INFO {json.dumps(info_reports(shot_dir))}", flush=True)
        print("INFO: DONE", flush=True)
        while_writes_refused(timer_guard.quit_blender)  # quits once Blender lets it
        return None
    return 0.1


timer_guard.guarded_timer(tick, 1.0)
