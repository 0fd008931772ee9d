# SPDX-License-Identifier: GPL-2.0-or-later
"""The add-on's preferences panel: where a message about this Blender
(too old, newer than tested) stays visible after the console has scrolled."""
import bpy

from .report import log

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

    def draw(self, _context):
        if not _messages:
            self.layout.label(text="HBAO: Compositor > Add > Filter > HBAO; viewport: "
                                   "sidebar, HBAO tab")
        for message in _messages:
            for sentence in message.split(". "):
                self.layout.label(text=sentence.rstrip("."), icon="INFO")


def register():
    bpy.utils.register_class(HBAOPreferences)


def unregister():
    _messages.clear()
    bpy.utils.unregister_class(HBAOPreferences)
