# SPDX-License-Identifier: GPL-2.0-or-later
"""What each HBAO node's AO reads in a helper's render: the main Render
Result's passes handed over (handover.py) with the camera they were rendered
through, for each view of a stereo or multi-view render; or, when
re-compositing with new settings, the passes the last render kept."""
import contextlib
import math

from . import (ao_cache, camera_time, exr_passes, handover, layer_passes, strip_cameras,
               view_cameras)
from . import camera as camera_model
from .planning import node_names
from .report import log, post_node_messages


def _evaluated(obj, depsgraph):
    if obj is None:
        return None
    try:
        return obj.evaluated_get(depsgraph)
    except (RuntimeError, ReferenceError, TypeError):
        return obj


@contextlib.contextmanager
def _at_camera_time(engine, depsgraph, main):
    """The helper's depsgraph, which Blender evaluates at the whole frame,
    evaluated at camera_time.of(main) instead where that differs (the linked
    cameras' animation then is that time's: up to 0.16 of AO off before,
    found by an exploratory run), and at its own time again after."""
    evaluated = depsgraph.scene_eval
    frame, subframe = evaluated.frame_current, evaluated.frame_subframe
    time = camera_time.of(main)
    if time == frame + subframe:
        yield
        return
    whole = math.floor(time)
    engine.frame_set(whole, time - whole)
    try:
        yield
    finally:
        engine.frame_set(frame, subframe)


def _cameras(engine, depsgraph, main):
    """{view name: camera description} of the render that has just ended;
    the one view None without Stereoscopy. The camera is the scene's, or a
    sequencer strip's override (strip_cameras.py)."""
    camera = _evaluated(strip_cameras.rendered_camera(main), depsgraph)
    views = view_cameras.rendered_views(main)
    if views is None:
        return {None: camera_model.camera_for_render_result(main, camera)}
    if camera is None:
        raise camera_model.CameraError(f"scene {main.name!r} has no camera", "No camera: AO off",
                                       None)
    return {name: view_cameras.camera_of_view(engine, main, camera, name,
                                              lambda obj: _evaluated(obj, depsgraph))
            for name, _suffix in views}


def handed_over(engine, depsgraph, helper, main, jobs, warnings, report):
    """(inputs_of, timings, views): the passes of the render that has just
    ended, saved and read back; inputs_of(job, view) gives a job's
    (AOInputs, depth, normal, ExtraPasses or None) in `view` of `views` (the
    one view None without Stereoscopy); report(text): a warning for the
    render's report."""
    # Fail early, before the save, if a library is missing.
    exr_passes.load_library()
    with _at_camera_time(engine, depsgraph, main):
        cameras = _cameras(engine, depsgraph, main)
    views = view_cameras.rendered_views(main)
    channels, timings = handover.read_main_passes(main, jobs, views)
    if views is None:
        channels = {None: channels}
    extra, extra_warnings = layer_passes.read(helper, main, jobs, timings)
    for warning in extra_warnings:
        report(f"HBAO {warning}")
        log(warning)
    if extra_warnings:  # the nodes' status lines show them with the plan's
        post_node_messages(main.name, node_names(main), warnings + extra_warnings)

    def inputs_of(job, view):
        depth = channels[view][("depth", job.layer)]
        normal = channels[view][("normal", job.layer)] if job.with_normal else None
        inputs = ao_cache.AOInputs(job.params, cameras[view], layer_passes.settings_of(job, extra),
                                   (depth, normal) + layer_passes.arrays_of(job, extra))
        return inputs, depth, normal, extra

    return inputs_of, timings, list(cameras)


def kept(main, request, cache):
    """(inputs_of, timings, views) as handed_over's, from the passes that the
    last render handed over and `cache` keeps (re-compositing with new
    settings, recomposite.py, which leaves stereo renders alone): no save and
    no read; the changed nodes' AO is in the cache already."""

    def inputs_of(job, _view):
        entry = cache.entry(ao_cache.key(main.name, job.pass_name))
        if entry is None:
            raise RuntimeError(f"the passes of {job.node_name!r} are no longer kept: render "
                               f"again")
        kept_inputs = entry[0]
        inputs = ao_cache.AOInputs(job.params, kept_inputs.camera, kept_inputs.settings,
                                   kept_inputs.arrays)
        extra = layer_passes.extra_of(kept_inputs.settings, kept_inputs.arrays)
        return inputs, kept_inputs.arrays[0], kept_inputs.arrays[1], extra

    return inputs_of, {"kept": request.ao_seconds}, [None]
