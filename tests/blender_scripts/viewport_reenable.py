# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in a Blender window (xvfb) by tests/test_viewport.py: the preview
turned on in the 3D view, then the add-on disabled and enabled again from
Preferences (each step in its own tick of the event loop, as an artist's
clicks are). Enabling registers the add-on where it may not read the file's
data; the view, still "on", must preview again without a toggle. Prints
'HANDLER <when> <bool>' (the preview's draw handler) and 'REENABLE: DONE'.
(Maximizing the view from such a script made Blender 3.4 crash under Xvfb
when it left the maximized screen, with the add-on's preview off too: the
maximized view's settings were checked by hand, not here.)

  blender --factory-startup --addons hbao --python viewport_reenable.py
"""
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import timer_guard  # noqa: E402

state = {"tick": 0}


def view_3d(window):
    return max((a for a in window.screen.areas if a.type == "VIEW_3D"),
               key=lambda a: a.width * a.height)


def override(window):
    area = view_3d(window)
    region = [r for r in area.regions if r.type == "WINDOW"][-1]
    return bpy.context.temp_override(window=window, screen=window.screen, area=area,
                                     region=region)


def handler(when):
    draw = sys.modules["hbao.viewport.draw"]  # after enabling: the module loaded again
    print(f"HANDLER {when} {draw.handler_registered()}", flush=True)


def tick():
    window = bpy.context.window_manager.windows[0]
    step = state["tick"]
    state["tick"] += 1
    if step == 0:
        with override(window):
            bpy.ops.hbao.viewport_preview_toggle()
        handler("on")
    elif step == 1:
        bpy.ops.preferences.addon_disable(module="hbao")
    elif step == 2:
        bpy.ops.preferences.addon_enable(module="hbao")
    elif step == 3:
        pass  # the timers run in order: the add-on's new one after this one
    elif step == 4:
        handler("enabled again")
        print("REENABLE: DONE", flush=True)
        timer_guard.quit_blender()
        return None
    return 0.3


timer_guard.guarded_timer(tick, 0.5)
