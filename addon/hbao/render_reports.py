# SPDX-License-Identifier: GPL-2.0-or-later
"""The engine's warnings in the Info editor and the status bar after an F12
render. Blender 3.4 drops the reports of a scene that the compositor renders
(the helper scene), so the engine also posts them (report.py) and a timer
re-reports them once no render job runs. Only the reports of an operator
that the event system finishes reach Blender's window manager (those of an
operator run from Python stay with the caller), so the operator is modal:
it reports on its first timer event."""
import bpy

from . import report, ui_timers, writes
from .callback_guard import never_raises

_POLL_S = 0.25


class HBAO_OT_render_report(bpy.types.Operator):
    """What the HBAO add-on met during the last render"""
    bl_idname = "hbao.render_report"
    bl_label = "HBAO Render Report"
    bl_options = {"INTERNAL"}

    def invoke(self, context, _event):
        self._timer = context.window_manager.event_timer_add(0.01, window=context.window)
        context.window_manager.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        context.window_manager.event_timer_remove(self._timer)
        for text in report.take_render_reports():
            self.report({"WARNING"}, text)
        return {"FINISHED"}


def _show_reports():
    windows = bpy.context.window_manager.windows
    with bpy.context.temp_override(window=windows[0], screen=windows[0].screen):
        bpy.ops.hbao.render_report("INVOKE_DEFAULT")


@never_raises("show the render's reports in the Info editor", result=_POLL_S)
def _poll():
    if report.has_render_reports() and not bpy.app.is_job_running("RENDER"):
        try:
            # Not asked first: one more operator poll right after a render,
            # while a callback of the render's thread may still run, is
            # one more chance of the overlap that leaves the refusal stuck
            # (a fresh-clone run of session 57 met it twice while this
            # asked). A refusal raises, below.
            writes.run_writing(_show_reports, ask=False)
        except (RuntimeError, IndexError, AttributeError) as error:
            if writes.writes_refused(error):
                return _POLL_S  # they wait for the next tick
            # never break the artist's session; the console has the messages
            report.log(f"could not show the render's reports in the Info editor: {error}")
            report.take_render_reports()
    return _POLL_S


def register():
    bpy.utils.register_class(HBAO_OT_render_report)
    # `-b` has no Info editor: the console has every message already.
    ui_timers.start(_poll, _POLL_S)


def unregister():
    ui_timers.stop(_poll)
    bpy.utils.unregister_class(HBAO_OT_render_report)
    report.take_render_reports()
