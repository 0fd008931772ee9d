# SPDX-License-Identifier: GPL-2.0-or-later
"""The helper scene's render engine: renders nothing itself, but publishes
one AO pass "HBAO <n>" per HBAO node of the tree it serves, computed by
libhbao from the main Render Result's Depth and Normal passes; a pass holds
the occlusion, 1 - AO (pass_encoding.py).

Anything that goes wrong leaves the pass at 0 (no AO) with a message: the
render always completes."""
import time

import bpy
import numpy as np

from . import camera as camera_model
from . import (ao_cache, compat, exr_passes, handover, job_inputs, layer_passes, native,
               pass_encoding, recomposite, render_record, scratch_files, strip_cameras,
               timing_line)
from .callback_guard import never_raises
from .helper_lookup import ENGINE_IDNAME, is_helper, pass_names_for_helper
from .helper_scene import rendered_for_a_scene, scene_for_render
from .node import hbao_nodes, pass_name
from .group_layout import GROUP_TREE_VERSION, layout_of
from .planning import node_names, plan, tell_all_nodes
from .report import log, post_render_report

# The prefix of the passes this engine fills (node.pass_name's).
PASS_PREFIX = "HBAO "
# The last render's passes and AO, reused for the same passes and settings,
# and by re-compositing (recomposite.py).
_cache = ao_cache.last_render


def _original(scene):
    return scene.original if hasattr(scene, "original") else scene


def compute_passes(engine, depsgraph, width, height, request=None):
    """{(view, pass name): bottom-up (height, width) AO} for the helper being
    rendered (the view None without Stereoscopy): for the render of its main
    scene, or for `request` (recomposite.Request) from the passes of the
    last render."""
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
    native.load_library()
    if request:
        inputs_of, timings, views = job_inputs.kept(main, request, _cache)
    else:
        inputs_of, timings, views = job_inputs.handed_over(
            engine, depsgraph, helper, main, jobs, warnings, lambda text: _report(engine, text))

    results = {}
    # Esc: Blender asks through test_break(); the passes say no AO and
    # the render ends as Blender decides (the scratch file goes as the
    # render_helper's removals_after block ends).
    if engine.test_break():
        log("render cancelled: no AO computed")
        _cache.clear()
        return {}
    compute_time = 0.0
    timings["threads"] = max(job.threads for job in jobs)  # (the same for every job)
    fresh = {}
    every_job = [(view, job) for view in views for job in jobs]
    for index, (view, job) in enumerate(every_job):
        if engine.test_break():
            log("render cancelled: AO left out")
            _cache.clear()
            return {}
        engine.update_stats("HBAO", f"{job.node_name}: computing AO ({index + 1}/"
                                    f"{len(every_job)})")
        inputs, depth, normal, extra = inputs_of(job, view)
        # A border render without its crop: the main Render Result is the
        # whole frame (background outside the border), the helper's only
        # the border. The AO is the whole frame's, cut to the border.
        border = camera_model.uncropped_border(main, depth.shape, (height, width))
        if depth.shape != (height, width) and border is None:
            raise RuntimeError(f"the Render Result is {depth.shape[1]}x{depth.shape[0]}, the "
                               f"helper scene renders {width}x{height}")
        compute_start = time.perf_counter()
        key = ao_cache.key(main.name, job.pass_name, view)
        ao = _cache.get(key, inputs)
        if ao is None:
            ao = layer_passes.compute(job, depth, normal, inputs.camera, extra)
            for note in native.last_notes():  # (this thread's compute)
                log(f"node {job.node_name!r}: {note}")
                _report(engine, f"HBAO: node {job.node_name!r}: {note}")
        else:
            timings["cached"] = timings.get("cached", 0) + 1
        fresh[key] = (inputs, ao)
        if border is not None:  # bottom-up rows, as the border's y
            x0, x1, y0, y1 = border
            ao = np.ascontiguousarray(ao[y0:y1, x0:x1])
        results[(view, job.pass_name)] = ao
        compute_time += time.perf_counter() - compute_start
        engine.update_progress((index + 1) / len(every_job))
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
HELPER_NOT_FOR_RENDERING = ("\"{helper}\" is the HBAO add-on's helper scene and "
                            "renders nothing by itself. Switch back to scene \"{main}\" and "
                            "render that.")
# What an artist who picked this engine for a scene of their own is told.
NOT_FOR_RENDERING = ("\"{label}\" is the HBAO add-on's internal engine and renders "
                     "nothing. Choose Cycles or EEVEE as the Render Engine (Render Properties), "
                     "and add the HBAO node in the Compositor.")


# A node's status line when a native library cannot be loaded (the full
# text, in the tooltip and the render's report, says what to do).
LIBRARY_SHORT = "Library not loaded: AO off"


def main_of(helper, request):
    """The main scene a render of `helper` is for (the request's, when
    re-compositing), or None."""
    return bpy.data.scenes.get(request.main) if request else scene_for_render(helper)


INTERRUPTED = "stopped while the AO was computed: this frame renders without AO"


def pass_layouts(main):
    """{pass name: the layout of its node's group} for `main`'s HBAO nodes
    (pass_encoding: the pass holds the occlusion, or for an older group, as
    a scene linked from an older file has, the AO)."""
    try:
        nodes = hbao_nodes(compat.compositor_tree(main)) if main is not None else []
        return {pass_name(node): layout_of(node) for node in nodes}
    except Exception as error:  # the render must complete: the current layout's
        log(f"could not read the HBAO nodes' group layouts: {error}")
        return {}


def _fill_passes(result, results, width, height, layouts):
    """Each registered AO pass of `result` gets its computed AO, or no AO,
    as its node's group reads it (layouts: pass_layouts)."""
    stereo = any(view is not None for view, _name in results)
    for layer in result.layers:
        for render_pass in layer.passes:
            if not render_pass.name.startswith(PASS_PREFIX):
                continue
            layout = layouts.get(render_pass.name, GROUP_TREE_VERSION)
            view = result.views[render_pass.view_id].name if stereo else None
            ao = results.get((view, render_pass.name))
            if ao is None or ao.size != width * height:
                values = np.full((height, width), pass_encoding.no_ao_for_layout(layout),
                                 np.float32)
            else:
                values = pass_encoding.pass_for_layout(ao, layout)
            render_pass.rect.foreach_set(values.reshape(-1))


def render_helper(engine, depsgraph):
    """HBAOPassEngine.render(): fill every registered AO pass, "no AO" where it failed."""
    scene = _original(depsgraph.scene)
    request = recomposite.request_for(scene)
    main = scene_for_render(scene) if is_helper(scene) else None
    if request is None and (main is None or not rendered_for_a_scene(scene)):
        if strip_cameras.in_a_job(scene):  # the artist rendered it
            _report_failure(engine, HELPER_NOT_FOR_RENDERING.format(helper=scene.name,
                                                                    main=main.name)
                            if main is not None
                            else NOT_FOR_RENDERING.format(label=HBAOPassEngine.bl_label))
        else:  # the node's place says why (node_place)
            log(f"{scene.name!r} rendered through a Render Layers node that the HBAO hook does "
                f"not serve: its AO passes say no AO")
        # Its passes say "no AO" (0): a compositor that renders this scene
        # through a Render Layers node the hook does not serve (5.3: in a
        # nested group) keeps its image as it is.
        result = engine.begin_result(0, 0, engine.resolution_x, engine.resolution_y)
        try:
            _fill_passes(result, {}, result.resolution_x, result.resolution_y,
                         pass_layouts(main))
        finally:
            engine.end_result(result)
        return
    start = time.perf_counter()
    engine.hbao_timings = {}
    # The result's own size: a border render cropped to its region is
    # smaller than engine.resolution_x/y (the full frame).
    result = engine.begin_result(0, 0, engine.resolution_x, engine.resolution_y)
    width, height = result.resolution_x, result.resolution_y
    filled = False
    layouts = {}
    try:
        layouts = pass_layouts(main_of(scene, request))
        try:
            # The scratch files go once the AO is computed (scratch_files.removals_after).
            with scratch_files.removals_after():
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
        except Exception as error:  # the render must complete: no AO
            results = {}
            _cache.clear()
            detail = f"{type(error).__name__}: {error}. Rendering without AO."
            _report_failure(engine, detail)
            tell_all_nodes(main_of(scene, request), "Error: AO off (see Info)", detail)
        write_start = time.perf_counter()
        _fill_passes(result, results, width, height, layouts)
        filled = True
    finally:
        try:
            if not filled:
                # Interrupted (bpy: Ctrl-C raises KeyboardInterrupt here):
                # the passes say no AO.
                log(INTERRUPTED)
                _fill_passes(result, {}, width, height, layouts)
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
@never_raises("release the library's memory after the render")
def _on_render_end(*_args):
    native.release_memory()  # kept from frame to frame of a render (a fifth of a frame)


_HANDLERS = (bpy.app.handlers.render_complete, bpy.app.handlers.render_cancel)


def register():
    if "bl_rna" not in HBAOPassEngine.__dict__:  # kept by unregister, below
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
    if not bpy.app.is_job_running("RENDER"):  # (3.4 crashed: blender-integration.md)
        bpy.utils.unregister_class(HBAOPassEngine)
