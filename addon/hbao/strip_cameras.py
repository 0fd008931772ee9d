# SPDX-License-Identifier: GPL-2.0-or-later
"""The camera a Video Sequencer scene strip renders its scene through.

A scene strip with a Camera override renders its scene with that camera,
not the scene's own, but nothing in the strip scene's render says so:
Blender passes the override to the scene's render (RE_RenderFrame's
camera_override) but not to the scenes its compositor renders, so the
helper's engine sees no override, and the saved Render Result carries no
camera name before the render ends. What the add-on can see is the nesting
of render jobs: the sequencer's scene starts its job, then each strip's
scene starts one of its own inside it (render_init .. render_complete or
render_cancel, handlers.py), at the frame the strip maps to. The strips of
the enclosing job's scene that show this scene at that scene's current
frame name the camera."""
import bpy

from .camera import CameraError
from .report import log

# The scenes whose render jobs run now, by name, outermost first.
_jobs = []


def job_started(scene):
    """render_init: `scene`'s job begins (inside the jobs still running)."""
    if scene.name in _jobs:  # an earlier job of it never ended: what it held ended too
        del _jobs[_jobs.index(scene.name):]
    _jobs.append(scene.name)


def job_ended(scene):
    """render_complete or render_cancel: `scene`'s job ends, and with it any
    job inside it."""
    if scene.name in _jobs:
        del _jobs[len(_jobs) - 1 - _jobs[::-1].index(scene.name):]


def forget_jobs():
    """A file is loaded: no job of the old one runs."""
    del _jobs[:]


def _strips(scene):
    """Every strip of `scene`'s sequencer, inside meta strips too (5.0
    renamed sequences_all to strips_all)."""
    editor = getattr(scene, "sequence_editor", None)
    if editor is None:
        return []
    strips = getattr(editor, "strips_all", None)
    return list(strips if strips is not None else getattr(editor, "sequences_all", []))


def _shows(strip, scene, frame):
    """Whether `strip` renders `scene` through a camera at the sequencer's
    `frame` (a strip whose input is the scene's own sequencer does not)."""
    return (strip.type == "SCENE" and strip.scene == scene and not strip.mute
            and getattr(strip, "scene_input", "CAMERA") == "CAMERA"
            and strip.frame_final_start <= frame < strip.frame_final_end)


def strip_overrides(scenes):
    """The Camera overrides of the strips of any scene that show one of
    `scenes`."""
    cameras = []
    for other in bpy.data.scenes:
        for strip in _strips(other):
            camera = getattr(strip, "scene_camera", None)
            if strip.type == "SCENE" and strip.scene in scenes and camera is not None:
                cameras.append(camera)
    return cameras


class AmbiguousStrips(CameraError):
    """Several strips show the scene now, through different cameras."""


def override_for(scene):
    """The camera that a sequencer strip renders `scene` through now, or None
    for the scene's own (no strip: a render of the scene itself). Raises
    AmbiguousStrips where strips at the same frame use different cameras:
    which of them is rendering cannot be told."""
    if scene.name not in _jobs:
        return None
    at = len(_jobs) - 1 - _jobs[::-1].index(scene.name)
    outer = bpy.data.scenes.get(_jobs[at - 1]) if at > 0 else None
    if outer is None:
        return None
    frame = outer.frame_current
    cameras = []
    for strip in _strips(outer):
        if _shows(strip, scene, frame):
            camera = getattr(strip, "scene_camera", None) or scene.camera
            if camera not in cameras:
                cameras.append(camera)
    if len(cameras) > 1:
        names = ", ".join(sorted(repr(getattr(camera, "name", None)) for camera in cameras))
        raise AmbiguousStrips(
            f"the Video Sequencer of scene {outer.name!r} shows scene {scene.name!r} at frame "
            f"{frame} in strips with different cameras ({names}): which one is rendering "
            f"cannot be told. Give each camera's strip its own frames, or a copy of the scene")
    camera = cameras[0] if cameras else None
    return camera if camera != scene.camera else None


def rendered_camera(scene):
    """The camera `scene` is rendered through now: a strip's override
    (override_for), else its own."""
    camera = override_for(scene)
    if camera is None:
        return scene.camera
    log(f"{scene.name!r} is rendered by a sequencer strip through camera {camera.name!r}: "
        f"the AO uses it")
    return camera
