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
render_cancel, handlers.py), at the frame the strip maps to. The strips that
the enclosing job's scene shows at its current frame (inside meta strips and
through strips whose input is another scene's sequencer too; not muted, nor
on a muted channel or in a muted meta; not below an opaque Replace strip,
unless only such a strip shows this scene, as an effect's input may) and
that show this scene at its current frame name the camera. The frame a strip
shows is worked out for strips at their own speed; where none matches (speed
or retiming changed), every strip shown now counts.

Not seen: the sequencer's Rendered preview in a window renders its scene
strips without a render job around them, so they get the scene camera's AO."""
import contextlib

import bpy

from . import compat
from .camera import CameraError
from .report import log

# The render jobs running now, outermost first: [scene name, whether its
# first frame has begun (render_pre)].
_jobs = []


def job_started(scene):
    """render_init: `scene`'s job begins (inside the jobs still running). A
    job whose frame never began has ended: an animation that could not start
    (a movie it cannot write, ...) calls neither render_complete nor
    render_cancel, and every job inside another begins after its frame has."""
    _jobs[:] = [job for job in _jobs if job[1] and job[0] != scene.name]
    _jobs.append([scene.name, False])


def frame_started(scene):
    """render_pre: a frame of `scene`'s job begins."""
    for job in reversed(_jobs):
        if job[0] == scene.name:
            job[1] = True
            return


def _innermost_job(scene):
    """The index in _jobs of `scene`'s innermost job, or None."""
    names = [name for name, _began in _jobs]
    return len(names) - 1 - names[::-1].index(scene.name) if scene.name in names else None


def in_a_job(scene):
    """Whether a render job of `scene` runs now: a render the artist (or a
    script) started, not one of a scene that a compositor renders."""
    return _innermost_job(scene) is not None


def job_ended(scene):
    """render_complete or render_cancel: `scene`'s job ends, and with it any
    job inside it."""
    at = _innermost_job(scene)
    if at is not None:
        del _jobs[at:]


def jobs_running():
    """Whether any render job runs now (handlers.py: not while one does)."""
    return bool(_jobs)


def forget_jobs():
    """A file is loaded: no job of the old one runs."""
    del _jobs[:]


def _children(holder):
    """The strips of a sequence editor or meta strip, not those inside
    them (5.0 renamed sequences to strips)."""
    strips = getattr(holder, "strips", None)
    return list(strips if strips is not None else getattr(holder, "sequences", []))


def every_strip(holder, unmuted=False):
    """The strips of `holder`, inside its meta strips too; `unmuted`: only
    those a render shows, neither muted nor in a muted channel or meta strip."""
    for strip in _children(holder):
        if unmuted and (strip.mute or _channel_muted(holder, strip.channel)):
            continue
        yield strip
        if strip.type == "META":
            yield from every_strip(strip, unmuted)


def _channel_muted(holder, number):
    channels = getattr(holder, "channels", None)  # 3.3+
    try:
        return bool(channels is not None and channels[number].mute)
    except (IndexError, KeyError, TypeError):
        return False


def _shown(holder, frame, covered):
    """The strips of `holder` (an editor or meta) that show at `frame`; with
    `covered` False, only from the top channel down to the first that
    replaces what lies below it (Blender renders those below only as an
    effect strip's inputs)."""
    for strip in sorted(_children(holder), key=lambda strip: -strip.channel):
        first, past_last = compat.strip_shown_frames(strip)
        if strip.mute or _channel_muted(holder, strip.channel) or not first <= frame < past_last:
            continue
        if strip.type == "META":
            yield from _shown(strip, frame, covered)
        else:
            yield strip
        if not covered and getattr(strip, "blend_type", None) == "REPLACE" \
                and getattr(strip, "blend_alpha", 1.0) >= 1.0:
            return


def _scene_frame(strip, frame):
    """The frame of its scene that scene strip `strip` shows at its
    sequencer's `frame`, for a strip at its own speed."""
    content_start, trimmed = compat.strip_content_start(strip)
    return strip.scene.frame_start + frame - content_start + trimmed


def _showing(sequencer_scene, frame, scene, covered=False, depth=0):
    """[(strip, the frame of `scene` it shows)] of the scene strips that show
    `scene` through a camera when `sequencer_scene`'s sequencer shows `frame`
    (_shown's `covered`)."""
    editor = getattr(sequencer_scene, "sequence_editor", None)
    if editor is None or depth > 8:
        return []
    found = []
    for strip in _shown(editor, frame, covered):
        if strip.type != "SCENE" or strip.scene is None:
            continue
        if getattr(strip, "scene_input", "CAMERA") == "SEQUENCER":
            if strip.scene != sequencer_scene:
                found += _showing(strip.scene, _scene_frame(strip, frame), scene, covered,
                                  depth + 1)
        elif strip.scene == scene:
            found.append((strip, _scene_frame(strip, frame)))
    return found


# While a sync of every helper runs (walking_strips_once): [None, or
# _overrides_by_scene() once the first helper asked]. Walking a 3000-strip
# sequencer once for each of 50 helpers took most of a 0.5 s sync.
_walk = None


@contextlib.contextmanager
def walking_strips_once():
    global _walk
    outer = _walk  # (inside another: its walk serves)
    _walk = outer if outer is not None else [None]
    try:
        yield
    finally:
        _walk = outer


def _overrides_by_scene():
    """{scene pointer: [(the strip's place in the walk, its Camera override)]}
    of the strips of every scene."""
    found = {}
    place = 0
    for other in bpy.data.scenes:
        editor = getattr(other, "sequence_editor", None)
        for strip in every_strip(editor) if editor is not None else ():
            camera = getattr(strip, "scene_camera", None)
            if strip.type == "SCENE" and strip.scene is not None and camera is not None:
                found.setdefault(strip.scene.as_pointer(), []).append((place, camera))
                place += 1
    return found


def strip_overrides(scenes):
    """The Camera overrides of the strips of any scene that show one of
    `scenes`, in the file's order."""
    if _walk is None:
        index = _overrides_by_scene()
    else:
        if _walk[0] is None:
            _walk[0] = _overrides_by_scene()
        index = _walk[0]
    pairs = sorted(pair for scene in {scene.as_pointer() for scene in scenes}
                   for pair in index.get(scene, ()))
    return [camera for _place, camera in pairs]


class AmbiguousStrips(CameraError):
    """Several strips show the scene now, through different cameras."""


def override_for(scene):
    """The camera that a sequencer strip renders `scene` through now, or None
    for the scene's own (no strip: a render of the scene itself). Raises
    AmbiguousStrips where strips at the same frame use different cameras:
    which of them is rendering cannot be told."""
    at = _innermost_job(scene)
    outer = bpy.data.scenes.get(_jobs[at - 1][0]) if at else None  # (None or 0: no outer job)
    if outer is None:
        return None
    showing = _showing(outer, outer.frame_current, scene) or \
        _showing(outer, outer.frame_current, scene, covered=True)
    now = scene.frame_current + scene.frame_subframe
    strips = [strip for strip, frame in showing if abs(frame - now) < 1e-3] or \
        [strip for strip, _frame in showing]
    cameras = []
    for strip in strips:
        camera = getattr(strip, "scene_camera", None) or scene.camera
        if camera not in cameras:
            cameras.append(camera)
    if len(cameras) > 1:
        names = ", ".join(repr(name) for name in sorted(getattr(camera, "name", "none")
                                                        for camera in cameras))
        strip_names = ", ".join(repr(name) for name in sorted(strip.name for strip in strips))
        raise AmbiguousStrips(
            f"the Video Sequencer strips {strip_names} show scene {scene.name!r} at its frame "
            f"{scene.frame_current} through different cameras ({names}): which one is "
            f"rendering cannot be told. Give each camera's strip its own frames, or a copy of "
            f"the scene")
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
