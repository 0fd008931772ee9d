# SPDX-License-Identifier: GPL-2.0-or-later
"""No window shows one of the add-on's internal scenes (a helper, or its
guard-band or back-face scene). Scene > Delete shows the scene before the
deleted one in Blender's list, and the internal scenes' names start with a
dot, so they come first: deleting the active scene showed the artist a
helper, which then kept the deleted scene's helper in the file (a window is
a user) and, saved so, made `blender -b file -f 1` render the helper. A
window found on one goes to the scene it serves, else the first of the
artist's scenes (a new one where none is left). The scene selector's search
finds the internal scenes too: a switch to one (no handler fires for it) is
watched on the message bus."""
import bpy

from . import extra_renders
from .helper_lookup import is_helper, scenes_served_by
from .report import log

_OWNER = object()  # the message bus's key for watch()


def is_internal(scene):
    return is_helper(scene) or extra_renders.is_extra(scene)


def shown_in_a_window(scene):
    manager = bpy.context.window_manager
    return manager is not None and any(window.scene == scene for window in manager.windows)


def _helpers_of(internal):
    """The helper scenes `internal` belongs to (itself, for a helper)."""
    if is_helper(internal):
        return [internal]
    return [helper for helper in bpy.data.scenes if is_helper(helper)
            and any(extra_renders.scene_of(helper, kind) == internal
                    for kind in extra_renders.KINDS)]


def _artist_scene_for(internal):
    served = [scene for helper in _helpers_of(internal) for scene in scenes_served_by(helper)]
    candidates = served + list(bpy.data.scenes)
    scene = next((scene for scene in candidates if not is_internal(scene)), None)
    return scene if scene is not None else bpy.data.scenes.new("Scene")


def leave_internal_scenes():
    """Move every window that shows an internal scene to an artist's scene.
    Main thread only."""
    manager = bpy.context.window_manager
    for window in manager.windows if manager is not None else ():
        internal = window.scene
        if internal is None or not is_internal(internal):
            continue
        scene = _artist_scene_for(internal)
        window.scene = scene
        log(f"the window showed the add-on's internal scene {internal.name!r} "
            f"(a scene was deleted?); it shows {scene.name!r} now")


def shows_an_internal_scene():
    manager = bpy.context.window_manager
    return manager is not None and any(
        window.scene is not None and is_internal(window.scene) for window in manager.windows)


def watch(notify):
    """(Re)subscribe notify() to a window's scene switch: loading a file
    clears the message bus."""
    bpy.msgbus.clear_by_owner(_OWNER)
    bpy.msgbus.subscribe_rna(key=(bpy.types.Window, "scene"), owner=_OWNER, args=(),
                             notify=notify)


def unwatch():
    bpy.msgbus.clear_by_owner(_OWNER)
