# SPDX-License-Identifier: GPL-2.0-or-later
"""The add-on's polling timers: each runs in Blender's main thread every so
many seconds while the add-on is enabled in a window, across file loads
(persistent); `-b` has no window, and there the render handlers do their
work instead. The one place that rule lives (node_status, render_reports,
memory_hold)."""
import bpy


def start(poll, interval):
    """Have Blender call `poll` (which returns when to run again) after
    `interval` seconds, where Blender has a window; once per function."""
    if not bpy.app.background and not bpy.app.timers.is_registered(poll):
        bpy.app.timers.register(poll, first_interval=interval, persistent=True)


def stop(poll):
    """Stop start()'s timer, where one runs."""
    if bpy.app.timers.is_registered(poll):
        bpy.app.timers.unregister(poll)
