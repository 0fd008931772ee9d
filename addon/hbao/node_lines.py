# SPDX-License-Identifier: GPL-2.0-or-later
"""The lines of text under the HBAO node's settings (what the render hook
said, whether the AO shown is current, where the node lies): a short form
that fits the node, the full text as its tooltip and, on a click, in the
Info editor."""
import bpy
from bpy.props import StringProperty

from . import ui_text


def draw(layout, short, details, icon):
    """A line under the node's settings, if `short` says anything: a
    borderless button whose tooltip (and a click: the Info editor) gives the
    full text that the short line stands for."""
    if not short:
        return
    text = ui_text.status_line(short)
    if not HBAO_OT_node_status.is_registered:  # the add-on disabled, its node type kept
        layout.label(text=text, icon=icon)
        return
    button = layout.operator(HBAO_OT_node_status.bl_idname, text=text, icon=icon, emboss=False)
    button.details = details or short


class HBAO_OT_node_status(bpy.types.Operator):
    """What the render hook said about this HBAO node"""
    bl_idname = "hbao.node_status"
    bl_label = "HBAO Node Status"
    bl_options = {"INTERNAL"}

    details: StringProperty(options={"SKIP_SAVE"})

    @classmethod
    def description(cls, _context, properties):
        return properties.details

    def execute(self, _context):
        for line in self.details.splitlines():
            self.report({"WARNING"}, f"HBAO {line}")
        return {"FINISHED"}
