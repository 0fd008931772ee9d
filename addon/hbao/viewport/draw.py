# SPDX-License-Identifier: GPL-2.0-or-later
"""The draw handler: registered while at least one 3D view has the preview on,
removed as soon as none has, so that the preview costs nothing when off.

It runs in POST_VIEW, where the view's depth buffer is still bound: the depth
is read back (the gpu module of 3.4 to 5.x exposes no depth texture of the
viewport; see scripts/bench_viewport.py for what the round trip costs),
linearised, turned into AO and multiplied over the view.
"""
import functools
from time import perf_counter

import bpy
import gpu
from bpy.app.handlers import persistent

from ..callback_guard import never_raises
from ..report import log
from . import pipeline, projection, view_entries

SHADINGS = {"SOLID", "MATERIAL"}

_handler = None
# Region pointer -> AOPipeline; each keeps targets the size of its region.
_pipelines = {}
_reported_errors = set()
# Area pointer -> why its preview draws nothing (the sidebar panel shows it);
# gone once the view draws again.
_view_errors = {}
# Region pointer -> its preview's last frame in ms, where Blender draws with
# a software renderer (software_renderer(); the panel shows it), and the
# time the sidebar was last asked to show.
_frame_ms = {}
_shown_ms = {}


def _forget_error(area):
    if area is not None:
        _view_errors.pop(area.as_pointer(), None)


def view_error(area):
    """Why the preview of the 3D view in `area` failed the last time it was
    drawn, or None."""
    return _view_errors.get(area.as_pointer()) if area is not None else None


@functools.cache
def software_renderer():
    """Whether Blender draws with a software renderer (Mesa's llvmpipe on a
    machine without a GPU, or without its driver): the preview's passes then
    run on the CPU and take about a second a frame at 1920x1080 on 2 cores
    (docs/speed.md), so the panel says how long they take. Asked once: the
    device does not change while Blender runs."""
    return gpu.platform.device_type_get() == "SOFTWARE"


def frame_ms(area):
    """The preview's last frame in the 3D view in `area` in ms (the slowest
    of a quad view's four), timed on a software renderer only; or None."""
    if area is None:
        return None
    times = [_frame_ms[region.as_pointer()] for region in area.regions
             if region.type == "WINDOW" and region.as_pointer() in _frame_ms]
    return max(times) if times else None


def _note_frame_ms(area, region, milliseconds):
    """Keep the frame time; ask the sidebar for a redraw where it differs by
    a tenth or more from the time it was last asked to show (not every
    frame: the sidebar need not redraw with the view)."""
    key = region.as_pointer()
    _frame_ms[key] = milliseconds
    shown = _shown_ms.get(key)
    if shown is None or abs(milliseconds - shown) > 0.1 * shown:
        _shown_ms[key] = milliseconds
        for sidebar in area.regions:
            if sidebar.type == "UI":
                sidebar.tag_redraw()


def handler_registered():
    return _handler is not None


def sync_handler():
    """Add the draw handler if any view has the preview on, remove it if none has."""
    global _handler
    wanted = view_entries.any_enabled()
    if wanted and _handler is None:
        _handler = bpy.types.SpaceView3D.draw_handler_add(_draw, (), "WINDOW", "POST_VIEW")
    elif not wanted and _handler is not None:
        bpy.types.SpaceView3D.draw_handler_remove(_handler, "WINDOW")
        _handler = None
        _forget_views()
    _redraw_3d_views()


@persistent
@never_raises("turn the viewport preview on or off for the file opened")
def sync_after_load(*_args):
    """load_post: a file saved with the preview on turns it on; one without turns it off."""
    sync_handler()


def _redraw_3d_views():
    window_manager = getattr(bpy.context, "window_manager", None)
    for window in getattr(window_manager, "windows", ()):
        for area in window.screen.areas:
            if area.type == "VIEW_3D":
                area.tag_redraw()


def not_drawn(space):
    """Why the preview cannot draw in 3D view `space` (the panel says it),
    or None. Solid shading's X-ray below alpha 1 writes no depth (the
    preview drew nothing there, an exploratory run)."""
    shading = space.shading
    if shading.type not in SHADINGS:
        # (it said "Solid or Material Preview only", which did not say what
        # to do; a review's find)
        return ("No AO in this shading: switch the view to Solid or Material Preview "
                "shading")
    if shading.type == "SOLID" and shading.show_xray and shading.xray_alpha < 1.0:
        return "No AO through X-ray: turn X-ray off or its Alpha to 1"
    return None


def _forget_region(region):
    """Drop a region's targets and frame times: its view is not drawn (the
    preview off in it, or a shading it cannot draw) while another view's
    preview keeps the handler on. They were kept until every view was off,
    some 230 MB of textures at 4K a view (a review's find)."""
    key = region.as_pointer() if region is not None else None
    for per_region in (_pipelines, _frame_ms, _shown_ms):
        per_region.pop(key, None)


def _draw():
    context = bpy.context
    space = context.space_data
    region_3d = context.region_data
    if space is None or region_3d is None or not_drawn(space) is not None:
        _forget_error(context.area)  # not drawn: nothing failed
        _forget_region(context.region)
        return
    view_settings = view_entries.find(context.screen, context.area)
    if view_settings is None or not view_settings.enabled:
        _forget_error(context.area)
        _forget_region(context.region)
        return
    try:
        key = context.region.as_pointer()
        ao_pipeline = _pipelines.get(key)
        if ao_pipeline is None:
            ao_pipeline = _pipelines[key] = pipeline.AOPipeline()
        if len(_pipelines) > 1:
            _forget_closed_views(context.window_manager)
        software = software_renderer()
        milliseconds = draw_preview(ao_pipeline, region_3d.window_matrix,
                                    view_settings.params(), timed=software)
        if milliseconds is not None:
            _note_frame_ms(context.area, context.region, milliseconds)
        _view_errors.pop(context.area.as_pointer(), None)
    except Exception as error:  # never let the preview break the viewport
        message = str(error) or type(error).__name__
        area_key = context.area.as_pointer()
        if _view_errors.get(area_key) != message:
            _view_errors[area_key] = message
            for region in context.area.regions:  # the sidebar shows it
                if region.type == "UI":
                    region.tag_redraw()
        if message not in _reported_errors:
            _reported_errors.add(message)
            log(f"viewport preview failed: {type(error).__name__}: {message}")


def _forget_closed_views(window_manager):
    """Drop the targets and frame times of regions that no longer exist (a
    closed 3D view, another workspace's screen). Run while more than one
    view has targets; the last view's are dropped when the preview is
    turned off."""
    open_regions = {region.as_pointer()
                    for window in getattr(window_manager, "windows", ())
                    for area in window.screen.areas if area.type == "VIEW_3D"
                    for region in area.regions if region.type == "WINDOW"}
    for per_region in (_pipelines, _frame_ms, _shown_ms):
        for key in list(per_region):
            if key not in open_regions:
                del per_region[key]


def _forget_views():
    for per_region in (_pipelines, _frame_ms, _shown_ms):
        per_region.clear()


def draw_preview(ao_pipeline, matrix, params, timed=False, reuse=True):
    """AO of the bound framebuffer's depth (drawn with projection `matrix`),
    multiplied over it, using `ao_pipeline`'s targets; with `reuse`, the AO
    of the pipeline's last frame where the view, `matrix`, `params` and the
    depth are that frame's (AOPipeline.kept_ao: only the composite runs).
    Also the unit that scripts/bench_viewport_blender.py times (reuse off).
    `timed`: returns the ms from the depth read back (which waits for
    Blender's own drawing) until the composite is issued, for a frame whose
    AO was computed; else None."""
    framebuffer = gpu.state.active_framebuffer_get()
    x, y, width, height = gpu.state.viewport_get()
    if width < 1 or height < 1:
        return None
    depth = framebuffer.read_depth(x, y, width, height)
    started = perf_counter()
    depth.dimensions = width * height
    key = (x, y, width, height, tuple(tuple(row) for row in matrix), sorted(params.items()))
    ao_texture = ao_pipeline.kept_ao(key, depth) if reuse else None
    computed = ao_texture is None

    depth_test = gpu.state.depth_test_get()
    depth_mask = gpu.state.depth_mask_get()
    gpu.state.depth_test_set("NONE")
    gpu.state.depth_mask_set(False)
    try:
        if computed:
            depth_buffer_texture = gpu.types.GPUTexture((width, height), format="R32F",
                                                        data=depth)
            frame = projection.frame_from_projection_matrix(matrix, width, height)
            linear_depth = ao_pipeline.linearize(depth_buffer_texture,
                                                 projection.depth_coefficients(matrix),
                                                 half=bool(params.get("half_resolution")))
            ao_texture = ao_pipeline.ambient_occlusion(
                linear_depth, frame, params,
                buffer_precision=projection.depth_buffer_precision(matrix))
            ao_pipeline.keep(key, depth, ao_texture)
        # Our passes bound their own framebuffers; draw back into the view.
        gpu.state.viewport_set(x, y, width, height)
        pipeline.composite(ao_texture, params["strength"], (x, y))
    finally:
        gpu.state.depth_mask_set(depth_mask)
        gpu.state.depth_test_set(depth_test)
    # Timed on a software renderer only, which runs the passes as they are
    # issued: a pixel read back after them (to wait for them) added 3 %.
    return (perf_counter() - started) * 1000.0 if timed and computed else None


def unregister():
    global _handler
    if _handler is not None:
        bpy.types.SpaceView3D.draw_handler_remove(_handler, "WINDOW")
        _handler = None
    _forget_views()
    pipeline.release()
