# SPDX-License-Identifier: GPL-2.0-or-later
"""The render hook: how AO computed in Python reaches Blender's compositor.

Python cannot run per pixel inside the compositor, but Blender renders every
scene that a Render Layers node of the compositor tree points at after the
main scene's engine has finished and before compositing. So each scene that
uses HBAO nodes gets a helper scene (".HBAO passes <scene>") rendered by
HBAOPassEngine, and a managed, collapsed Render Layers node pointing at it.
The engine's render() saves the main Render Result (Depth, Normal) to an
uncompressed EXR, computes one AO pass per HBAO node with that node's settings
at the frame being rendered, and publishes them as passes "HBAO <n>": outputs
of the managed Render Layers node, linked to each node's hidden "HBAO Pass"
input. The node's group multiplies Image by it. See
docs/blender-integration.md for the verified facts this relies on.

Anything that goes wrong leaves the pass at 1 (no AO) with a message: the
render always completes.
"""
import os
import tempfile
import threading
import time

import bpy
import numpy as np

from . import camera as camera_model
from . import compat, exr_passes, native
from .node import (AO_PASS_INPUT, DEPTH_INPUT, NORMAL_INPUT, VALUE_INPUTS, hbao_nodes,
                   is_hbao_node, next_pass_index, pass_name)

ENGINE_IDNAME = "HBAO_PASSES"
HELPER_SCENE_PREFIX = ".HBAO passes "
# ID property on the helper scene: the scene it serves.
MAIN_SCENE_KEY = "hbao_main_scene"
# ID property on the Render Layers node the add-on manages.
MANAGED_NODE_KEY = "hbao_managed"
MANAGED_NODE_NAME = "HBAO Passes"
# How far below the first HBAO node the managed node goes (node editor units).
HBAO_NODE_CLEARANCE = 480
LOG_PREFIX = "HBAO:"
# Render settings copied from the main scene so that the helper's result has
# the main Render Result's size.
_SYNCED_RENDER_SETTINGS = (
    "resolution_x", "resolution_y", "resolution_percentage", "pixel_aspect_x",
    "pixel_aspect_y", "use_border", "use_crop_to_border", "border_min_x", "border_max_x",
    "border_min_y", "border_max_y", "fps", "fps_base")
# Image settings save_render() reads from the main scene; restored after use.
_SAVED_IMAGE_SETTINGS = ("file_format", "color_mode", "color_depth", "exr_codec",
                         "use_preview", "use_zbuffer", "views_format")


def log(message):
    print(f"{LOG_PREFIX} {message}", flush=True)


def _in_main_thread():
    return threading.current_thread() is threading.main_thread()


# --- finding things -----------------------------------------------------------

def _upstream(socket):
    """The output socket that really feeds `socket`, through reroutes; None if unlinked."""
    seen = 0
    while socket is not None and socket.is_linked and seen < 64:
        link = socket.links[0]
        if link.is_muted or not link.is_valid:
            return None
        from_socket = link.from_socket
        if from_socket.node.bl_idname == "NodeReroute":
            socket = from_socket.node.inputs[0]
            seen += 1
            continue
        return from_socket
    return None


def managed_node(tree):
    if tree is None:
        return None
    for node in tree.nodes:
        if node.bl_idname == "CompositorNodeRLayers" and node.get(MANAGED_NODE_KEY):
            return node
    return None


def main_scene_of(helper):
    main = helper.get(MAIN_SCENE_KEY)
    return main if isinstance(main, bpy.types.Scene) else None


def helper_scene_of(scene):
    node = managed_node(compat.compositor_tree(scene))
    if node is not None and node.scene is not None and main_scene_of(node.scene) == scene:
        return node.scene
    for candidate in bpy.data.scenes:
        if main_scene_of(candidate) == scene:
            return candidate
    return None


def pass_names_for_helper(helper):
    """The AO passes the helper scene's engine publishes (one per HBAO node)."""
    main = main_scene_of(helper)
    if main is None:
        return []
    return [pass_name(node) for node in hbao_nodes(compat.compositor_tree(main))]


# --- keeping the hook in sync (main thread) ----------------------------------

def _set_if_different(owner, attribute, value):
    if getattr(owner, attribute) != value:
        setattr(owner, attribute, value)
        return True
    return False


def _ensure_helper_scene(scene):
    helper = helper_scene_of(scene)
    if helper is None:
        helper = bpy.data.scenes.new(HELPER_SCENE_PREFIX + scene.name)
        helper[MAIN_SCENE_KEY] = scene
        log(f"created helper scene {helper.name!r} for {scene.name!r}")
    _set_if_different(helper.render, "engine", ENGINE_IDNAME)
    if not compat.HAS_COMPOSITING_NODE_GROUP and helper.use_nodes:
        helper.use_nodes = False
    for attribute in _SYNCED_RENDER_SETTINGS:
        _set_if_different(helper.render, attribute, getattr(scene.render, attribute))
    # The helper's render needs a camera; the main camera itself, so that its
    # animation is evaluated at the frame being rendered in the helper's depsgraph.
    camera = scene.camera
    if camera is not None:
        if helper.collection.objects.get(camera.name) != camera:
            helper.collection.objects.link(camera)
        _set_if_different(helper, "camera", camera)
    for obj in list(helper.collection.objects):
        if obj != camera:
            helper.collection.objects.unlink(obj)
    return helper


def _enable_needed_passes(scene, tree):
    """Turn on the Depth/Normal pass a linked HBAO node reads but the view layer lacks."""
    messages = []
    for node in hbao_nodes(tree):
        if node.mute:
            continue
        for input_name, attribute, label in ((DEPTH_INPUT, "use_pass_z", "Depth"),
                                             (NORMAL_INPUT, "use_pass_normal", "Normal")):
            socket = node.inputs.get(input_name)
            if socket is None or not socket.is_linked:
                continue
            source = socket.links[0].from_node
            while source.bl_idname == "NodeReroute" and source.inputs[0].is_linked:
                source = source.inputs[0].links[0].from_node
            if source.bl_idname != "CompositorNodeRLayers" or source.get(MANAGED_NODE_KEY):
                continue
            source_scene = source.scene or scene
            view_layer = source_scene.view_layers.get(source.layer)
            if view_layer is not None and not getattr(view_layer, attribute):
                setattr(view_layer, attribute, True)
                message = (f"enabled the {label} pass of view layer {view_layer.name!r} "
                           f"for node {node.name!r}")
                messages.append(message)
                log(message)
                if _in_main_thread():
                    node.status = f"{label} pass enabled on {view_layer.name}"
    return messages


def _refresh_render_layers_sockets(node, helper):
    """Make the managed Render Layers node list the engine's current passes."""
    # Re-assigning the layer makes Blender ask the engine for its passes again.
    view_layer_name = helper.view_layers[0].name
    node.layer = view_layer_name


def sync(scene):
    """Create, update or remove the hook of `scene` to match its HBAO nodes.
    Main thread only for structural changes; returns a list of messages."""
    tree = compat.compositor_tree(scene)
    if tree is None or main_scene_of(scene) is not None:
        return []
    nodes = hbao_nodes(tree)
    rlayers = managed_node(tree)
    if not nodes:
        if rlayers is not None:
            tree.nodes.remove(rlayers)
            log(f"removed the HBAO hook of {scene.name!r} (no HBAO node left)")
        helper = helper_scene_of(scene)
        if helper is not None:
            bpy.data.scenes.remove(helper)
        return []

    messages = _enable_needed_passes(scene, tree)
    seen = set()
    for node in nodes:
        if node.pass_index == 0 or node.pass_index in seen:
            node.pass_index = next_pass_index(tree, exclude=node)
        seen.add(node.pass_index)

    helper = _ensure_helper_scene(scene)
    if rlayers is None:
        rlayers = tree.nodes.new("CompositorNodeRLayers")
        rlayers[MANAGED_NODE_KEY] = True
        rlayers.name = MANAGED_NODE_NAME
        rlayers.label = "HBAO passes (managed by the HBAO add-on)"
        # Below the first HBAO node (about 420 units tall with its options),
        # clear of the artist's Render Layers node on its left.
        rlayers.location = (nodes[0].location.x, nodes[0].location.y - HBAO_NODE_CLEARANCE)
        rlayers.hide = True
    if rlayers.scene != helper:
        rlayers.scene = helper
    # Missing (new node) or unavailable (file loaded before the engine was
    # registered): ask the engine for its passes again.
    if any(rlayers.outputs.get(pass_name(node)) is None
           or not rlayers.outputs[pass_name(node)].enabled for node in nodes):
        _refresh_render_layers_sockets(rlayers, helper)
    for output in rlayers.outputs:
        if not output.is_linked:
            _set_if_different(output, "hide", True)
    for node in nodes:
        output = rlayers.outputs.get(pass_name(node))
        target = node.inputs.get(AO_PASS_INPUT)
        if output is None or target is None:
            messages.append(f"node {node.name!r}: its AO pass socket is not available yet")
            continue
        # Blender unhides linked sockets and refuses to hide them, so this one
        # link stays visible; the collapsed Render Layers node shows only it.
        if not (target.is_linked and target.links[0].from_socket == output):
            for link in list(output.links):
                tree.links.remove(link)
            tree.links.new(output, target)
    return messages


def sync_all():
    for scene in list(bpy.data.scenes):
        if main_scene_of(scene) is not None:
            if main_scene_of(scene).name not in bpy.data.scenes:
                bpy.data.scenes.remove(scene)
            continue
        tree = compat.compositor_tree(scene)
        if hbao_nodes(tree) or managed_node(tree) is not None:
            try:
                sync(scene)
            except Exception as error:  # never break the user's session
                log(f"could not update the HBAO hook of {scene.name!r}: {error}")


_sync_scheduled = False


def _timer_sync():
    global _sync_scheduled
    _sync_scheduled = False
    sync_all()
    return None


def schedule_sync():
    """Sync soon, from the main loop (node callbacks must not edit the tree)."""
    global _sync_scheduled
    if not _sync_scheduled and not bpy.app.background:
        _sync_scheduled = True
        bpy.app.timers.register(_timer_sync, first_interval=0.0)


@bpy.app.handlers.persistent
def _on_load_post(*_args):
    sync_all()


@bpy.app.handlers.persistent
def _on_save_pre(*_args):
    # Background scripts get no timer: the hook is built at the latest here, so
    # that `blender -b file.blend -f N` finds it in the file.
    sync_all()


@bpy.app.handlers.persistent
def _on_render_pre(scene, *_args):
    if main_scene_of(scene) is not None:
        return
    if not hbao_nodes(compat.compositor_tree(scene)):
        return
    try:
        if _in_main_thread():
            sync(scene)  # -b renders: the only chance to build the hook
        else:
            # F12 runs this in the render job: only plain settings, no new data.
            helper = helper_scene_of(scene)
            if helper is not None:
                for attribute in _SYNCED_RENDER_SETTINGS:
                    _set_if_different(helper.render, attribute, getattr(scene.render, attribute))
            _enable_needed_passes(scene, compat.compositor_tree(scene))
    except Exception as error:
        log(f"could not prepare the HBAO hook of {scene.name!r}: {error}")


@bpy.app.handlers.persistent
def _on_depsgraph_update_post(scene, *_args):
    if main_scene_of(scene) is not None or not _in_main_thread():
        return
    tree = compat.compositor_tree(scene)
    if hbao_nodes(tree) or managed_node(tree) is not None:
        schedule_sync()


# --- reading the artist's values ------------------------------------------------

def _animated(id_data, owner, attribute, frame, fallback):
    try:
        path = owner.path_from_id(attribute)
    except ValueError:
        return fallback
    fcurve = compat.find_fcurve(id_data, path)
    return fcurve.evaluate(frame) if fcurve is not None else fallback


def _socket_value(tree, socket, frame, warnings):
    source = _upstream(socket)
    if source is None:
        return _animated(tree, socket, "default_value", frame, socket.default_value)
    if source.node.bl_idname == "CompositorNodeValue":
        return _animated(tree, source, "default_value", frame, source.default_value)
    warnings.append(f"{socket.node.name}: {socket.name} comes from {source.node.name!r}; "
                    f"only a Value node can drive it, using {socket.default_value:g}")
    return socket.default_value


def node_params(node, frame, warnings):
    """The params dict for native.compute_ao() from the node at `frame`."""
    tree = node.id_data
    params = {
        "falloff": node.falloff,
        "integration": node.integration,
        "half_resolution": int(node.half_resolution),
        "blur_sharpness": float(node.blur_sharpness),
    }
    for name, (key, _default, minimum, maximum, integer) in VALUE_INPUTS.items():
        value = float(_socket_value(tree, node.inputs[name], frame, warnings))
        if not np.isfinite(value):
            raise ValueError(f"{node.name}: {name} is not a number")
        value = min(max(value, minimum), maximum)
        params[key] = int(round(value)) if integer else value
    return params


def _pass_source(socket, scene, expected):
    """(view layer name, error) of the Render Layers pass feeding `socket`."""
    source = _upstream(socket)
    if source is None:
        return None, None
    node = source.node
    if node.bl_idname != "CompositorNodeRLayers" or node.get(MANAGED_NODE_KEY):
        return None, f"{socket.name} must come straight from a Render Layers node"
    if node.scene is not None and node.scene != scene:
        return None, f"{socket.name} comes from another scene ({node.scene.name})"
    if source.identifier != expected and source.name != expected:
        return None, f"{socket.name} is linked to the {source.name} pass, not {expected}"
    return node.layer, None


# --- the engine --------------------------------------------------------------------

class _Job:
    def __init__(self, node, layer, with_normal, params):
        self.node_name = node.name
        self.pass_name = pass_name(node)
        self.layer = layer
        self.with_normal = with_normal
        self.params = params


def _plan(main, frame):
    """The AO computations this frame needs: ([_Job], [warning])."""
    jobs, warnings = [], []
    for node in hbao_nodes(compat.compositor_tree(main)):
        if node.mute:
            continue
        if not any(output.is_linked for output in node.outputs):
            continue  # nobody looks at it: costs nothing
        depth_layer, error = _pass_source(node.inputs[DEPTH_INPUT], main, "Depth")
        if depth_layer is None:
            warnings.append(f"{node.name}: {error or 'Depth is not linked'}; AO = 1")
            continue
        normal_layer, error = _pass_source(node.inputs[NORMAL_INPUT], main, "Normal")
        if error:
            warnings.append(f"{node.name}: {error}; reconstructing normals from depth")
        try:
            params = node_params(node, frame, warnings)
        except ValueError as value_error:
            warnings.append(f"{value_error}; AO = 1")
            continue
        jobs.append(_Job(node, depth_layer, normal_layer == depth_layer, params))
        if normal_layer is not None and normal_layer != depth_layer:
            warnings.append(f"{node.name}: Normal comes from another view layer than Depth; "
                            f"reconstructing normals from depth")
    return jobs, warnings


def _render_result_image():
    for image in bpy.data.images:
        if image.type == "RENDER_RESULT":
            return image
    return None


def _scratch_path():
    folder = "/dev/shm" if os.path.isdir("/dev/shm") and os.access("/dev/shm", os.W_OK) \
        else tempfile.gettempdir()
    return os.path.join(folder, f"hbao-passes-{os.getpid()}-{threading.get_ident()}.exr")


def save_main_passes(main, path):
    """Write the main scene's current Render Result to `path`, uncompressed
    multilayer EXR, leaving the user's output settings as they were."""
    image = _render_result_image()
    if image is None:
        raise RuntimeError("Blender has no Render Result image to read the passes from")
    settings = main.render.image_settings
    saved = {name: getattr(settings, name) for name in _SAVED_IMAGE_SETTINGS
             if hasattr(settings, name)}
    try:
        settings.file_format = "OPEN_EXR_MULTILAYER"
        settings.color_depth = "32"
        settings.exr_codec = "NONE"
        if hasattr(settings, "use_preview"):
            settings.use_preview = False
        image.save_render(path, scene=main)
    finally:
        for name, value in saved.items():
            try:
                setattr(settings, name, value)
            except (TypeError, ValueError):
                pass  # an enum value not valid for the restored format is re-derived


def _evaluated_camera(main, depsgraph):
    camera = main.camera
    if camera is None:
        return None
    try:
        return camera.evaluated_get(depsgraph)
    except (RuntimeError, ReferenceError, TypeError):
        return camera


def compute_passes(engine, depsgraph, width, height):
    """{pass name: bottom-up (height, width) AO} for the helper being rendered."""
    helper = depsgraph.scene.original if hasattr(depsgraph.scene, "original") else depsgraph.scene
    main = main_scene_of(helper)
    if main is None:
        raise RuntimeError(f"scene {helper.name!r} is not an HBAO helper scene")
    frame = main.frame_current + main.frame_subframe
    jobs, warnings = _plan(main, frame)
    for warning in warnings:
        engine.report({"WARNING"}, f"HBAO {warning}")
        log(warning)
    if not jobs:
        return {}
    timings = {}
    # Fail early, before the save, if a library is missing.
    native.load_library()
    exr_passes.load_library()
    camera = camera_model.camera_for_render_result(main, _evaluated_camera(main, depsgraph))

    start = time.perf_counter()
    path = _scratch_path()
    try:
        save_main_passes(main, path)
        timings["save"] = time.perf_counter() - start
        # One decode pass: each layer's depth, and its normal as one
        # interleaved (height, width, 3) image, as libhbao reads it.
        groups = {}
        for job in jobs:
            groups[("depth", job.layer)] = [f"{job.layer}.Depth.Z"]
            if job.with_normal:
                groups[("normal", job.layer)] = [f"{job.layer}.Normal.{axis}" for axis in "XYZ"]
        read_start = time.perf_counter()
        channels = exr_passes.read_channel_groups(path, groups)
        timings["read"] = time.perf_counter() - read_start
    finally:
        if os.path.exists(path):
            os.remove(path)

    results = {}
    compute_time = 0.0
    for index, job in enumerate(jobs):
        engine.update_stats("HBAO", f"{job.node_name}: computing AO ({index + 1}/{len(jobs)})")
        depth = channels[("depth", job.layer)]
        if depth.shape != (height, width):
            raise RuntimeError(f"the Render Result is {depth.shape[1]}x{depth.shape[0]}, the "
                               f"helper scene renders {width}x{height}")
        normal = channels[("normal", job.layer)] if job.with_normal else None
        compute_start = time.perf_counter()
        # The EXR's rows run top-down, a render pass bottom-up: views flipped, no copy.
        results[job.pass_name] = native.compute_ao(
            depth[::-1], None if normal is None else normal[::-1], params=job.params,
            camera=camera, bottom_up=True)
        compute_time += time.perf_counter() - compute_start
        engine.update_progress((index + 1) / len(jobs))
    timings["ao"] = compute_time
    engine.hbao_timings = timings
    return results


def render_helper(engine, depsgraph):
    """HBAOPassEngine.render(): fill every registered AO pass, 1 where it failed."""
    start = time.perf_counter()
    engine.hbao_timings = {}
    # The result's own size: a border render cropped to its region is
    # smaller than engine.resolution_x/y (the full frame).
    result = engine.begin_result(0, 0, engine.resolution_x, engine.resolution_y)
    width, height = result.resolution_x, result.resolution_y
    try:
        try:
            results = compute_passes(engine, depsgraph, width, height)
        except (native.HBAOLibraryError, exr_passes.EXRLibraryError) as error:
            results = {}
            _report_failure(engine, f"{error} Rendering without AO.")
        except Exception as error:  # the render must complete: AO = 1
            results = {}
            _report_failure(engine, f"{type(error).__name__}: {error}. Rendering without AO.")
        write_start = time.perf_counter()
        for layer in result.layers:
            for render_pass in layer.passes:
                if not render_pass.name.startswith("HBAO "):
                    continue
                ao = results.get(render_pass.name)
                if ao is None or ao.size != width * height:
                    ao = np.ones((height, width), np.float32)
                render_pass.rect.foreach_set(ao.reshape(-1))
    finally:
        engine.end_result(result)
    timings = dict(engine.hbao_timings)
    timings["write"] = time.perf_counter() - write_start
    total = time.perf_counter() - start
    if results:
        handover = timings.get("save", 0) + timings.get("read", 0) + timings["write"]
        line = (f"{len(results)} AO pass(es) {width}x{height} in {total * 1000:.0f} ms: AO "
                f"{timings.get('ao', 0) * 1000:.0f} ms, pass hand-over {handover * 1000:.0f} ms "
                f"(save {timings.get('save', 0) * 1000:.0f}, read "
                f"{timings.get('read', 0) * 1000:.0f}, write {timings['write'] * 1000:.0f})")
        log(line)
        engine.update_stats("HBAO", line)


def _report_failure(engine, message):
    log(message)
    engine.report({"WARNING"}, f"HBAO: {message}")


class HBAOPassEngine(bpy.types.RenderEngine):
    """Renders nothing itself: publishes the AO of the main scene's HBAO nodes."""
    bl_idname = ENGINE_IDNAME
    bl_label = "HBAO Passes (internal)"
    bl_use_postprocess = True
    bl_use_preview = False

    def update_render_passes(self, scene=None, renderlayer=None):
        self.register_pass(scene, renderlayer, "Combined", 4, "RGBA", "COLOR")
        for name in pass_names_for_helper(scene.original if hasattr(scene, "original") else scene):
            self.register_pass(scene, renderlayer, name, 1, "X", "VALUE")

    def render(self, depsgraph):
        render_helper(self, depsgraph)


_HANDLERS = (
    (bpy.app.handlers.load_post, _on_load_post),
    (bpy.app.handlers.save_pre, _on_save_pre),
    (bpy.app.handlers.render_init, _on_render_pre),
    (bpy.app.handlers.render_pre, _on_render_pre),
    (bpy.app.handlers.depsgraph_update_post, _on_depsgraph_update_post),
)


def register():
    bpy.utils.register_class(HBAOPassEngine)
    for handlers, function in _HANDLERS:
        if function not in handlers:
            handlers.append(function)


def unregister():
    for handlers, function in _HANDLERS:
        if function in handlers:
            handlers.remove(function)
    bpy.utils.unregister_class(HBAOPassEngine)


__all__ = ["sync", "sync_all", "schedule_sync", "HBAOPassEngine", "is_hbao_node"]
