# SPDX-License-Identifier: GPL-2.0-or-later
"""The helper scene's render engine: renders nothing itself, but publishes
one AO pass "HBAO <n>" per HBAO node of the tree it serves, computed by
libhbao from the main Render Result's Depth and Normal passes.

Anything that goes wrong leaves the pass at 1 (no AO) with a message: the
render always completes."""
import time

import bpy
import numpy as np

from . import camera as camera_model
from . import (ao_cache, exr_passes, handover, layer_passes, native, recomposite, render_record,
               strip_cameras, timing_line)
from .helper_lookup import ENGINE_IDNAME, is_helper, pass_names_for_helper
from .helper_scene import rendered_for_a_scene, scene_for_render
from .planning import node_names, plan, tell_all_nodes
from .report import log, post_node_messages, post_render_report

# The prefix of the passes this engine fills (node.pass_name's).
PASS_PREFIX = "HBAO "
MULTIVIEW_UNSUPPORTED = ("stereo and multi-view renders get no AO yet (turn Stereoscopy off in "
                         "the Output properties for AO)")

# The last render's passes and AO, reused for the same passes and settings,
# and by re-compositing (recomposite.py).
_cache = ao_cache.last_render


def _evaluated_camera(main, depsgraph):
    camera = strip_cameras.rendered_camera(main)  # a sequencer strip's override too
    if camera is None:
        return None
    try:
        return camera.evaluated_get(depsgraph)
    except (RuntimeError, ReferenceError, TypeError):
        return camera


def _original(scene):
    return scene.original if hasattr(scene, "original") else scene


def _handed_over(engine, depsgraph, helper, main, jobs, warnings):
    """(inputs_of, timings): the passes of the render that has just ended,
    saved and read back; inputs_of(job) gives a job's (AOInputs, depth,
    normal, ExtraPasses or None)."""
    # Fail early, before the save, if a library is missing.
    exr_passes.load_library()
    camera = camera_model.camera_for_render_result(main, _evaluated_camera(main, depsgraph))
    channels, timings = handover.read_main_passes(main, jobs)
    extra, extra_warnings = layer_passes.read(helper, main, jobs, timings)
    for warning in extra_warnings:
        _report(engine, f"HBAO {warning}")
        log(warning)
    if extra_warnings:  # the nodes' status lines show them with the plan's
        post_node_messages(main.name, node_names(main), warnings + extra_warnings)

    def inputs_of(job):
        depth = channels[("depth", job.layer)]
        normal = channels[("normal", job.layer)] if job.with_normal else None
        inputs = ao_cache.AOInputs(job.params, camera, layer_passes.settings_of(job, extra),
                                   (depth, normal) + layer_passes.arrays_of(job, extra))
        return inputs, depth, normal, extra

    return inputs_of, timings


def _kept(main, request):
    """(inputs_of, timings) as _handed_over's, from the passes that the last
    render handed over (re-compositing with new settings, recomposite.py):
    no save and no read; the changed nodes' AO is in the cache already."""

    def inputs_of(job):
        entry = _cache.entry((main.name, job.pass_name))
        if entry is None:
            raise RuntimeError(f"the passes of {job.node_name!r} are no longer kept: render "
                               f"again")
        kept = entry[0]
        inputs = ao_cache.AOInputs(job.params, kept.camera, kept.settings, kept.arrays)
        extra = layer_passes.extra_of(kept.settings, kept.arrays)
        return inputs, kept.arrays[0], kept.arrays[1], extra

    return inputs_of, {"kept": request.ao_seconds}


def compute_passes(engine, depsgraph, width, height, request=None):
    """{pass name: bottom-up (height, width) AO} for the helper being
    rendered: for the render of its main scene, or for `request`
    (recomposite.Request) from the passes of the last render."""
    helper = _original(depsgraph.scene)
    main = main_of(helper, request)
    if main is None:
        raise RuntimeError(f"scene {helper.name!r} is not an HBAO helper scene")
    frame = request.frame if request else main.frame_current + main.frame_subframe
    jobs, warnings = plan(main, frame)
    render_record.remember(main.name, frame, jobs, node_names(main), main.as_pointer())
    for warning in warnings:
        _report(engine, f"HBAO {warning}")
        log(warning)
    if not jobs:
        if request is not None:
            request.completed = True
        return {}
    if main.render.use_multiview:
        # Each view would need its own passes and camera; the save of a
        # multi-view Render Result writes one file per view besides.
        raise RuntimeError(MULTIVIEW_UNSUPPORTED)
    native.load_library()
    if request:
        inputs_of, timings = _kept(main, request)
    else:
        inputs_of, timings = _handed_over(engine, depsgraph, helper, main, jobs, warnings)

    results = {}
    # Esc: Blender asks through test_break(); the passes are left at 1 and
    # the render ends as Blender decides (the scratch file goes as the
    # render_helper's removals_after block ends).
    if engine.test_break():
        log("render cancelled: no AO computed")
        _cache.clear()
        return {}
    compute_time = 0.0
    fresh = {}
    for index, job in enumerate(jobs):
        if engine.test_break():
            log("render cancelled: AO left out")
            _cache.clear()
            return {}
        engine.update_stats("HBAO", f"{job.node_name}: computing AO ({index + 1}/{len(jobs)})")
        inputs, depth, normal, extra = inputs_of(job)
        # A border render without its crop: the main Render Result is the
        # whole frame (background outside the border), the helper's only
        # the border. The AO is the whole frame's, cut to the border.
        border = camera_model.uncropped_border(main, depth.shape, (height, width))
        if depth.shape != (height, width) and border is None:
            raise RuntimeError(f"the Render Result is {depth.shape[1]}x{depth.shape[0]}, the "
                               f"helper scene renders {width}x{height}")
        compute_start = time.perf_counter()
        key = (main.name, job.pass_name)
        ao = _cache.get(key, inputs)
        if ao is None:
            ao = layer_passes.compute(job, depth, normal, inputs.camera, extra)
        else:
            timings["cached"] = timings.get("cached", 0) + 1
        fresh[key] = (inputs, ao)
        if border is not None:  # bottom-up rows, as the border's y
            x0, x1, y0, y1 = border
            ao = np.ascontiguousarray(ao[y0:y1, x0:x1])
        results[job.pass_name] = ao
        compute_time += time.perf_counter() - compute_start
        engine.update_progress((index + 1) / len(jobs))
    _cache.keep_only(fresh)
    timings["ao"] = compute_time
    engine.hbao_timings = timings
    if request is not None:
        request.completed = True
    return results


def _report(engine, text):
    """A warning in the render's report, and (report.py) in the Info editor."""
    engine.report({"WARNING"}, text)
    if not bpy.app.background:  # `-b`: the console has it; nothing would take it
        post_render_report(text)


def _report_failure(engine, message):
    log(message)
    _report(engine, f"HBAO: {message}")


# What an artist who renders the helper scene itself (made it the active
# scene) is told.
HELPER_NOT_FOR_RENDERING = ("HBAO: \"{helper}\" is the HBAO add-on's helper scene and "
                            "renders nothing by itself. Switch back to scene \"{main}\" and "
                            "render that.")
# What an artist who picked this engine for a scene of their own is told.
NOT_FOR_RENDERING = ("HBAO: \"{label}\" is the HBAO add-on's internal engine and renders "
                     "nothing. Choose Cycles or EEVEE as the Render Engine (Render Properties), "
                     "and add the HBAO node in the Compositor.")


# A node's status line when a native library cannot be loaded (the full
# text, in the tooltip and the render's report, says what to do).
LIBRARY_SHORT = "Library not loaded: AO off"


def main_of(helper, request):
    """The main scene a render of `helper` is for (the request's, when
    re-compositing), or None."""
    return bpy.data.scenes.get(request.main) if request else scene_for_render(helper)


def render_helper(engine, depsgraph):
    """HBAOPassEngine.render(): fill every registered AO pass, 1 where it failed."""
    scene = _original(depsgraph.scene)
    request = recomposite.request_for(scene)
    main = scene_for_render(scene) if is_helper(scene) else None
    if request is None and (main is None or not rendered_for_a_scene(scene)):
        message = (HELPER_NOT_FOR_RENDERING.format(helper=scene.name, main=main.name)
                   if main is not None
                   else NOT_FOR_RENDERING.format(label=HBAOPassEngine.bl_label))
        log(message)
        _report(engine, message)
        return
    start = time.perf_counter()
    engine.hbao_timings = {}
    # The result's own size: a border render cropped to its region is
    # smaller than engine.resolution_x/y (the full frame).
    result = engine.begin_result(0, 0, engine.resolution_x, engine.resolution_y)
    width, height = result.resolution_x, result.resolution_y
    try:
        try:
            # The scratch files go once the AO is computed (handover.removals_after).
            with handover.removals_after():
                results = compute_passes(engine, depsgraph, width, height, request)
        except (native.HBAOLibraryError, exr_passes.EXRLibraryError) as error:
            results = {}
            _cache.clear()  # nothing kept that this render's record would not match
            _report_failure(engine, f"{error} Rendering without AO.")
            tell_all_nodes(main_of(scene, request), LIBRARY_SHORT, f"{error} Rendering without AO.")
        except camera_model.CameraError as error:  # a camera the library cannot model
            results = {}
            _report_failure(engine, f"{error}. Rendering without AO.")
            tell_all_nodes(main_of(scene, request), "Camera: AO off",
                           f"{error}. Rendering without AO.")
        except Exception as error:  # the render must complete: AO = 1
            results = {}
            _cache.clear()
            detail = f"{type(error).__name__}: {error}. Rendering without AO."
            _report_failure(engine, detail)
            tell_all_nodes(main_of(scene, request), "Error: AO off (see Info)", detail)
        write_start = time.perf_counter()
        for layer in result.layers:
            for render_pass in layer.passes:
                if not render_pass.name.startswith(PASS_PREFIX):
                    continue
                ao = results.get(render_pass.name)
                if ao is None or ao.size != width * height:
                    ao = np.ones((height, width), np.float32)
                render_pass.rect.foreach_set(ao.reshape(-1))
    finally:
        engine.end_result(result)
    timings = dict(engine.hbao_timings)
    timings["write"] = time.perf_counter() - write_start
    if results:
        line = timing_line.format_line(len(results), width, height,
                                       time.perf_counter() - start, timings)
        log(line)
        engine.update_stats("HBAO", line)


class HBAOPassEngine(bpy.types.RenderEngine):
    """Renders nothing itself: publishes the AO of the main scene's HBAO nodes."""
    bl_idname = ENGINE_IDNAME
    # The Render Engine menu lists every engine (Python cannot hide one):
    # the label says it is not for the artist; render() says so too.
    bl_label = "HBAO Passes (internal, do not use)"
    bl_use_postprocess = True
    bl_use_preview = False

    def update_render_passes(self, scene=None, renderlayer=None):
        self.register_pass(scene, renderlayer, "Combined", 4, "RGBA", "COLOR")
        for name in pass_names_for_helper(_original(scene)):
            self.register_pass(scene, renderlayer, name, 1, "X", "VALUE")

    def render(self, depsgraph):
        render_helper(self, depsgraph)


@bpy.app.handlers.persistent
def _on_render_end(*_args):
    # The library keeps its working memory from frame to frame of a render
    # (a fifth of a frame's time); between renders it is given back.
    native.release_memory()


_HANDLERS = (bpy.app.handlers.render_complete, bpy.app.handlers.render_cancel)


def register():
    bpy.utils.register_class(HBAOPassEngine)
    for handlers in _HANDLERS:
        if _on_render_end not in handlers:
            handlers.append(_on_render_end)


def unregister():
    for handlers in _HANDLERS:
        if _on_render_end in handlers:
            handlers.remove(_on_render_end)
    _cache.clear()
    native.release_memory()
    bpy.utils.unregister_class(HBAOPassEngine)
