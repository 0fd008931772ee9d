# SPDX-License-Identifier: GPL-2.0-or-later
"""The window's areas for the UI scripts (ui_node.py, ui_disabled_node.py):
the largest area turned into the compositor's node editor, and a context
override for operators that need it."""
import bpy


def node_editor(window):
    area = max(window.screen.areas, key=lambda a: a.width * a.height)
    area.type = "NODE_EDITOR"
    area.ui_type = "CompositorNodeTree"
    return area


def override(window, area):
    region = next(r for r in area.regions if r.type == "WINDOW")
    return bpy.context.temp_override(window=window, screen=window.screen, area=area,
                                     region=region)
