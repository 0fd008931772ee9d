# SPDX-License-Identifier: GPL-2.0-or-later
"""The add-on's preferences for the scripts that set them (Keep Memory
After a Render: ui_memory_hold.py, ui_memory_in_use.py).

`--addons` enables the add-on for the session without an entry in the
preferences (as Blender's own enabling does: Addons.new()); the artist's
enabling in the preferences makes one, which holds the add-on's settings.
"""
import bpy


def hbao_preferences():
    """The add-on's AddonPreferences, its entry made where there is none."""
    addons = bpy.context.preferences.addons
    if "hbao" not in addons:
        addons.new().module = "hbao"
    return addons["hbao"].preferences
