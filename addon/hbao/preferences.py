# SPDX-License-Identifier: GPL-2.0-or-later
"""The add-on's preferences panel: where a message about this Blender
(too old, newer than tested) stays visible after the console has scrolled,
and how long the library's memory is kept after a render (memory_hold)."""
import bpy
from bpy.props import IntProperty

from . import ui_text
from .report import log

# Characters a line of the preferences holds at the window's usual width.
LINE_CHARACTERS = 90
# keep_memory_s's default (memory_hold.py: sessions 68 and 69 measured what it saves).
KEEP_MEMORY_DEFAULT_S = 60

# The package name Blender knows the add-on by: "hbao" as a legacy add-on,
# "bl_ext.<repository>.hbao" as an extension.
_ADDON_NAME = __package__
_messages = []


def show(message):
    """Print `message` and keep it in the preferences panel."""
    log(message)
    if message not in _messages:
        _messages.append(message)


class HBAOPreferences(bpy.types.AddonPreferences):
    bl_idname = _ADDON_NAME

    keep_memory_s: IntProperty(
        name="Keep Memory After a Render (Seconds)", default=KEEP_MEMORY_DEFAULT_S, min=0,
        max=3600,
        description="Seconds the AO library keeps its working memory (about 24 bytes a pixel: "
                    "50 MB at 1080p) after a render in this window, so that the next render or "
                    "changed node value does not wait for it; 0 gives it back at once. Renders "
                    "from the command line (-b) give it back at once")

    def draw(self, _context):
        layout = self.layout
        column = layout.column(align=True)
        column.label(text="Compositor node: Add > Filter > HBAO", icon="NODETREE")
        column.label(text="Viewport preview: 3D view sidebar (N), HBAO tab", icon="VIEW3D")
        _library_status(layout.column(align=True))
        layout.prop(self, "keep_memory_s")
        for message in _messages:
            for sentence in message.split(". "):
                layout.label(text=sentence.rstrip("."), icon="INFO")


def keep_memory_seconds():
    """The preference keep_memory_s, or its default where the add-on's
    preferences cannot be read."""
    addon = bpy.context.preferences.addons.get(_ADDON_NAME)
    preferences = getattr(addon, "preferences", None)
    return KEEP_MEMORY_DEFAULT_S if preferences is None else preferences.keep_memory_s


def _library_status(layout):
    """Whether the native libraries load (a missing one turns the AO off:
    the node and the preview say so when they run)."""
    from . import exr_passes, native  # not at import: they need no bpy, this module does
    for label, load in (("AO library", native.load_library),
                        ("EXR library", exr_passes.load_library)):
        try:
            load()
        except Exception as error:  # missing, or not this add-on's
            layout.label(text=f"{label}: not loaded, no AO", icon="ERROR")
            ui_text.labels(layout, str(error), LINE_CHARACTERS, "BLANK1")
        else:
            layout.label(text=f"{label}: loaded", icon="CHECKMARK")


def register():
    bpy.utils.register_class(HBAOPreferences)


def unregister():
    _messages.clear()
    bpy.utils.unregister_class(HBAOPreferences)
