# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in every Blender of the matrix by tests/test_addon.py (headless: bpy
has no window): the compositor's Add > Filter menu class of this Blender
draws the add-on's entry. Prints 'MENU <json>'.

  blender -b --addons hbao --python addon_menu.py
"""
import json
import sys

compat = sys.modules["hbao.compat"]
node_module = sys.modules["hbao.node"]
menu = compat.compositor_filter_menu()
draw_functions = getattr(menu.draw, "_draw_funcs", []) if menu is not None else []


class Recorder:
    """Stands in for a UILayout: records the operators drawn."""

    def __init__(self):
        self.operators = []

    def operator(self, idname, text="", **_kwargs):
        entry = type("Properties", (), {})()
        self.operators.append((idname, text, entry))
        return entry


class Space:
    tree_type = "CompositorNodeTree"


class Context:
    space_data = Space()


recorder = Recorder()
menu_entry = type("Menu", (), {"layout": recorder})()
for function in draw_functions:
    if function.__module__ == node_module.__name__:
        function(menu_entry, Context())
print("MENU " + json.dumps({
    "menu": menu.__name__ if menu is not None else None,
    "ours": [f.__name__ for f in draw_functions if f.__module__ == node_module.__name__],
    "entries": [(idname, text, getattr(entry, "type", None))
                for idname, text, entry in recorder.operators]}), flush=True)
