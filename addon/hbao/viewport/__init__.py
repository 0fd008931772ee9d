# SPDX-License-Identifier: GPL-2.0-or-later
"""Viewport preview: the HBAO of docs/algorithm.md in GLSL, multiplied over the
3D viewport in Solid and Material Preview shading, per 3D view, from the
sidebar's "HBAO" tab. No native library needed: it runs on the GPU.

    projection.py, shader_sources.py, camera_sources.py,
    normal_sources.py, horizon_sources.py             no bpy (plain pytest)
    shaders.py, pipeline.py                           gpu passes
    settings.py                                       per-view settings on the Screen
    view_entries.py                                   which settings are whose view
    view_swaps.py                                     views moved by Swap Areas (no bpy)
    draw.py                                           the draw handler (only while on)
    panel.py                                          sidebar panel and operator
"""
from ..callback_guard import never_raises

# bpy and the gpu modules are imported by register(), so that projection and
# shader_sources (and this package) import in plain Python.
_registered = False


def is_registered():
    return _registered


def register():
    global _registered
    if _registered:
        return
    import bpy

    from . import draw, panel, settings, view_entries
    settings.register()
    panel.register()
    view_entries.enabled_change_callbacks.append(draw.sync_handler)
    bpy.app.handlers.load_post.append(draw.sync_after_load)
    _registered = True
    if isinstance(bpy.data, bpy.types.BlendData):
        draw.sync_handler()
    elif not bpy.app.background:
        # Enabling the add-on (Preferences, addon_utils) registers it where
        # bpy.data may not be read: the views it finds on, re-enabled, would
        # stay blank until toggled. The sync waits for the main loop.
        bpy.app.timers.register(_sync_later, first_interval=0.0)


@never_raises("turn the viewport preview on for the views that had it")
def _sync_later():
    from . import draw
    if _registered:
        draw.sync_handler()
    return None  # once


def unregister():
    global _registered
    if not _registered:
        return
    import bpy

    from . import draw, panel, settings, view_entries
    while draw.sync_after_load in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(draw.sync_after_load)
    if draw.sync_handler in view_entries.enabled_change_callbacks:
        view_entries.enabled_change_callbacks.remove(draw.sync_handler)
    draw.unregister()
    panel.unregister()
    settings.unregister()
    _registered = False
