# SPDX-License-Identifier: GPL-2.0-or-later
"""HBAO: horizon-based ambient occlusion as a compositor node (Add > Filter >
HBAO) and a viewport preview, computed by the native library libhbao.

Importing the package needs no bpy: the modules that touch Blender are
imported by register(), so that parameters, native, exr_passes, camera and
viewport.projection/shader_sources work in plain Python (tests, benchmarks).

    bpy-free   parameters, library_loading, native, exr_passes, camera,
               timing_line, scratch_names, pass_encoding,
               viewport.projection, viewport.shader_sources
    Blender    compat (every version difference), compat_nodes, writes, preferences, node,
               node_status, helper_lookup, helper_scene, socket_values, planning, handover,
               helper_ao, engine, memory_hold, engine_guard, render_reports, handlers,
               viewport.*
"""

bl_info = {
    "name": "HBAO",
    "author": "HBAO contributors",
    "version": (0, 6, 0),
    "blender": (3, 4, 0),
    "location": "Compositor > Add > Filter > HBAO; 3D View > Sidebar > HBAO",
    "description": "Horizon-based ambient occlusion from the Depth and Normal passes",
    "category": "Compositing",
    "doc_url": "",
    "tracker_url": "",
    "support": "COMMUNITY",
}

# Modules registered in this order (unregistered in reverse). Kept across
# importlib.reload (Reload Scripts of an add-on enabled for the session only,
# `--addons`), which re-runs this file: reset, the modules it registered were
# unknown to a later unregister, which then let go of nothing (a review).
_registered = globals().get("_registered", [])


def sync(scene=None):
    """Build or update the render hook of `scene` (default: every scene) now.
    Scripts that add HBAO nodes in background mode may call it; renders call
    it themselves. Returns the hook's messages."""
    from . import helper_scene
    if scene is None:
        helper_scene.sync_all()
        return []
    return helper_scene.sync(scene)


def register():
    import bpy

    from . import compat, preferences
    preferences.register()
    message = compat.version_message()
    if message is not None:
        preferences.show(message)
        if not compat.version_is_new_enough():
            return  # the message says why; a traceback would not
    from . import (engine, engine_guard, handlers, memory_hold, node, node_setup, node_status,
                   pass_capture, recomposite, render_record, render_reports, report, writes)
    for module in (writes, node, node_status, node_setup, render_record, recomposite, engine,
                   memory_hold, engine_guard, render_reports, pass_capture, handlers):
        module.register()
        _registered.append(module)
    try:
        from . import viewport
        viewport.register()
        _registered.append(viewport)
    except Exception as error:  # the compositor node works without the preview
        report.log(f"the viewport preview could not be registered: {error}")
    if not isinstance(bpy.data, bpy.types.BlendData):
        return  # add-on enabled at startup: load_post syncs once a file is open
    sync()


def unregister():
    from . import hook_release, preferences, report
    if _registered:  # enabled for this Blender: a hook to let go of
        hook_release.release_all()
    while _registered:
        module = _registered.pop()
        try:
            module.unregister()
        except Exception as error:  # unregister the rest whatever one of them did
            report.log(f"{module.__name__} could not be unregistered: {error}")
    preferences.unregister()
