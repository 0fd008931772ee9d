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
from . import (compat, exr_passes, memory_hold, native, pass_encoding, recomposite, scratch_files,
               strip_cameras, timing_line)
from .helper_ao import cache, compute_passes, main_of, original, report_warning
from .helper_lookup import ENGINE_IDNAME, is_helper, pass_names_for_helper
from .helper_scene import rendered_for_a_scene, scene_for_render
from .node import hbao_nodes, pass_name
from .group_layout import GROUP_TREE_VERSION, layout_of
from .planning import tell_all_nodes
from .report import log

# The prefix of the passes this engine fills (node.pass_name's).
PASS_PREFIX = "HBAO "


def _report_failure(engine, message):
    log(message)
    report_warning(engine, f"HBAO: {message}")


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
    scene = original(depsgraph.scene)
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
            cache.clear()  # nothing kept that this render's record would not match
            _report_failure(engine, f"{error} Rendering without AO.")
            tell_all_nodes(main_of(scene, request), LIBRARY_SHORT, f"{error} Rendering without AO.")
        except camera_model.CameraError as error:  # a camera the library cannot model
            results = {}
            _report_failure(engine, f"{error}. Rendering without AO.")
            told = main_of(scene, request)
            tell_all_nodes(told, error.short, f"{error}. Rendering without AO.",
                           camera_model.scene_camera_cause(told, error) if told else None)
        except Exception as error:  # the render must complete: no AO
            results = {}
            cache.clear()
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
            memory_hold.release_if_inactive()
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
        for name in pass_names_for_helper(original(scene)):
            self.register_pass(scene, renderlayer, name, 1, "X", "VALUE")

    def render(self, depsgraph):
        render_helper(self, depsgraph)


def register():
    if "bl_rna" not in HBAOPassEngine.__dict__:  # kept by unregister, below
        bpy.utils.register_class(HBAOPassEngine)


def unregister():
    cache.clear()
    if not bpy.app.is_job_running("RENDER"):  # (3.4 crashed: blender-integration.md)
        bpy.utils.unregister_class(HBAOPassEngine)
