# SPDX-License-Identifier: GPL-2.0-or-later
"""The Info editor's reports, read as an artist copies them (run in a real
Blender window: ui_info_report.py, ui_stuck_writes.py)."""
import os

import bpy


def info_reports(shot_dir=None, shot_name="ui_info_report.png"):
    """The Info editor's reports, as Ctrl+C in it copies them: the
    window's largest area becomes the Info editor, its reports are selected
    and copied (info.select_all + info.report_copy) and read from the
    clipboard. With shot_dir, a screenshot of the window there."""
    window = bpy.context.window_manager.windows[0]
    area = max(window.screen.areas, key=lambda a: a.width * a.height)
    area.type = "INFO"
    region = next(r for r in area.regions if r.type == "WINDOW")
    bpy.context.window_manager.clipboard = ""
    with bpy.context.temp_override(window=window, screen=window.screen, area=area,
                                   region=region):
        bpy.ops.info.select_all(action="SELECT")
        bpy.ops.info.report_copy()
        bpy.ops.wm.redraw_timer(type="DRAW_WIN_SWAP", iterations=2)
    if shot_dir is not None:
        with bpy.context.temp_override(window=window, screen=window.screen):
            bpy.ops.screen.screenshot(filepath=os.path.join(shot_dir, shot_name),
                                      check_existing=False)
    return bpy.context.window_manager.clipboard
