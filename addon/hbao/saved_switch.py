# SPDX-License-Identifier: GPL-2.0-or-later
"""The add-on's scenes are saved switched off, for a Blender without it.

Blender renders every scene a compositor's Render Layers node points at
whose view layers are switched on for rendering. Without the add-on (a
render worker where nobody installed it), the helper scene's engine is
unknown, and Blender renders it with EEVEE instead: a worker with no OpenGL
at all (a bare container without Mesa) aborted on such a file after the
artist's render, where a plain Cycles file renders; the extra renders (guard
band, back faces) cost a Cycles render each for nothing. So a saved file
holds the view layers of those scenes off (Blender skips a scene with none
on), and the add-on switches them on again after the save and at every
render's start (helper_render_settings.copy, extra_renders.record_rendering),
any thread: a plain setting.

Not while a render runs: its compositor may reach the step where Blender
renders these scenes during the save (F12's job runs beside the window),
and would skip them, compositing the previous frame's AO (a review: a save
as F12 rendered frame 3 gave it frame 1's AO, silently). A file saved then
keeps them on, as files saved before this change."""
import bpy

from . import extra_renders, helper_scene
from .helper_lookup import is_helper

# (scene name, view layer name) of the layers switched off for the save
_switched = []


def _addon_scenes():
    return [scene for scene in bpy.data.scenes
            if scene.library is None and (is_helper(scene) or extra_renders.is_extra(scene))]


def before_save():
    """Switch the add-on's scenes' view layers off, to be saved so."""
    after_save()  # (a save that failed where Blender has no handler for it)
    if bpy.app.is_job_running("RENDER") or helper_scene.any_rendering():
        return
    for scene in _addon_scenes():
        for layer in scene.view_layers:
            if layer.use:
                layer.use = False
                _switched.append((scene.name, layer.name))


def after_save():
    """Switch on again what before_save switched off."""
    while _switched:
        scene_name, layer_name = _switched.pop()
        scene = bpy.data.scenes.get(scene_name)
        layer = scene.view_layers.get(layer_name) if scene is not None else None
        if layer is not None:
            layer.use = True
