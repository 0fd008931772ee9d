# SPDX-License-Identifier: GPL-2.0-or-later
"""The guard band's extra render (guard_geometry.py has its geometry): a
scene ".HBAO guard band <scene>" that holds the artist's collections (linked,
not copied) and a camera that follows the scene camera with a wider view,
rendered by Cycles at 1 sample with Depth and Normal only, and a managed
Render Layers node pointing at it. Blender renders the scenes of a
compositor tree's Render Layers nodes in the order of the tree's nodes, so
that node comes before the helper's: when the helper's engine runs, the
guard scene's Render Result holds this frame's passes."""
import bpy

from . import compat, guard_geometry
from .data_edits import set_if_different
from .report import log

GUARD_SCENE_PREFIX = ".HBAO guard band "
# ID property on the guard scene: it is one (the helper's name, for people).
GUARD_KEY = "hbao_guard_for"
# ID property on the helper scene: its guard scene.
HELPER_GUARD_KEY = "hbao_guard_scene"
# ID property on the guard's Render Layers node.
GUARD_NODE_KEY = "hbao_guard_node"
# ID property on the guard scene: how much wider its camera sees.
SCALE_KEY = "hbao_guard_scale"
CAMERA_SETTINGS = ("type", "lens", "sensor_width", "sensor_height", "sensor_fit", "shift_x",
                   "shift_y", "ortho_scale", "clip_start", "clip_end")


def is_guard(scene):
    return GUARD_KEY in scene.keys()


def guard_of(helper):
    guard = helper.get(HELPER_GUARD_KEY) if helper is not None else None
    return guard if isinstance(guard, bpy.types.Scene) else None


def wanted_fraction(nodes):
    """The widest band the tree's unmuted HBAO nodes ask for (fraction)."""
    return max([node.guard_band / 100.0 for node in nodes if not node.mute] or [0.0])


def guard_node(tree):
    if tree is None:
        return None
    for node in tree.nodes:
        if node.bl_idname == "CompositorNodeRLayers" and node.get(GUARD_NODE_KEY):
            return node
    return None


def copy_camera(main, guard):
    """The guard camera's settings from the scene camera's, widened. Plain
    values only: allowed in the render job's thread."""
    source = main.camera
    target = guard.camera
    if source is None or target is None or source.type != "CAMERA":
        return
    values = {name: getattr(source.data, name) for name in CAMERA_SETTINGS}
    widened = guard_geometry.widened_camera(values, guard.get(SCALE_KEY, 1.0))
    for name in CAMERA_SETTINGS:
        set_if_different(target.data, name, widened[name])
    set_if_different(target.data.dof, "use_dof", False)
    for name in ("pixel_aspect_x", "pixel_aspect_y"):
        set_if_different(guard.render, name, getattr(main.render, name))
    set_if_different(guard, "frame_current", main.frame_current)


def _configure_render(guard):
    render = guard.render
    set_if_different(render, "engine", "CYCLES")
    cycles = getattr(guard, "cycles", None)
    if cycles is not None:
        for name, value in (("samples", 1), ("use_denoising", False),
                            ("use_adaptive_sampling", False), ("max_bounces", 0),
                            ("filter_width", 0.01)):
            if hasattr(cycles, name):
                set_if_different(cycles, name, value)
    set_if_different(render, "use_motion_blur", False)
    settings = render.image_settings
    if settings.file_format != "OPEN_EXR_MULTILAYER":
        compat.set_multilayer_exr(settings)
        settings.color_depth = "32"
        settings.exr_codec = "NONE"
    view_layer = guard.view_layers[0]
    set_if_different(view_layer, "use_pass_z", True)
    set_if_different(view_layer, "use_pass_normal", True)
    if not compat.HAS_COMPOSITING_NODE_GROUP and guard.use_nodes:
        guard.use_nodes = False


def _link_contents(main, guard, guard_camera):
    """The artist's collections and loose objects, linked; nothing else.
    Returns whether anything was linked or unlinked."""
    changed = False
    children = list(main.collection.children)
    for collection in children:
        if guard.collection.children.get(collection.name) != collection:
            guard.collection.children.link(collection)
            changed = True
    for collection in list(guard.collection.children):
        if collection not in children:
            guard.collection.children.unlink(collection)
            changed = True
    objects = list(main.collection.objects) + [guard_camera]
    for obj in objects:
        if guard.collection.objects.get(obj.name) != obj:
            guard.collection.objects.link(obj)
            changed = True
    for obj in list(guard.collection.objects):
        if obj not in objects:
            guard.collection.objects.unlink(obj)
            changed = True
    return changed


def _mirror_exclusions(source, target):
    """The guard's view layer leaves out what the node's view layer does."""
    by_collection = {child.collection: child for child in target.children}
    for child in source.children:
        mirror = by_collection.get(child.collection)
        if mirror is not None:
            set_if_different(mirror, "exclude", child.exclude)
            _mirror_exclusions(child, mirror)


def _ensure_camera(main, guard):
    camera = guard.camera
    if camera is None:
        data = bpy.data.cameras.new(GUARD_SCENE_PREFIX + main.name)
        camera = bpy.data.objects.new(GUARD_SCENE_PREFIX + main.name, data)
        camera.constraints.new("COPY_TRANSFORMS")
        guard.camera = camera
    constraint = camera.constraints[0] if camera.constraints else None
    if constraint is not None and constraint.target != main.camera:
        constraint.target = main.camera
    return camera


def remove(helper, tree):
    node = guard_node(tree)
    if node is not None:
        tree.nodes.remove(node)
    guard = guard_of(helper)
    if guard is None:
        return
    camera = guard.camera
    del helper[HELPER_GUARD_KEY]
    bpy.data.scenes.remove(guard)
    if camera is not None and camera.users == 0:
        data = camera.data
        bpy.data.objects.remove(camera)
        if data is not None and data.users == 0:
            bpy.data.cameras.remove(data)
    log(f"removed the guard band render of {helper.name!r}")


def sync(main, tree, nodes, helper, view_layer):
    """Create, update or remove the guard scene of `helper` for `main`'s
    HBAO nodes; `view_layer` is the one whose collections it mirrors. Main
    thread only. Returns True when the helper's managed node must be made
    again, after the guard's (render order)."""
    fraction = wanted_fraction(nodes)
    if fraction <= 0.0 or main.camera is None:
        remove(helper, tree)
        return False
    guard = guard_of(helper)
    if guard is None:
        guard = bpy.data.scenes.new(GUARD_SCENE_PREFIX + main.name)
        guard[GUARD_KEY] = helper.name
        helper[HELPER_GUARD_KEY] = guard
        log(f"created the guard band render {guard.name!r} for {main.name!r}")
    _configure_render(guard)
    if guard.get(SCALE_KEY) != guard_geometry.guard_scale(fraction):
        guard[SCALE_KEY] = guard_geometry.guard_scale(fraction)
    guard_layers = guard.view_layers[0]
    if _link_contents(main, guard, _ensure_camera(main, guard)) \
            or guard_layers.layer_collection is None:
        # 5.3 syncs a new scene's layer collections only when asked
        compat.settle_new_scene(guard)
    if view_layer is not None and guard_layers.layer_collection is not None:
        _mirror_exclusions(view_layer.layer_collection, guard_layers.layer_collection)
    copy_camera(main, guard)
    node = guard_node(tree)
    if node is None:
        node = tree.nodes.new("CompositorNodeRLayers")
        node[GUARD_NODE_KEY] = True
        node.name = "HBAO Guard Band"
        node.label = "HBAO guard band (managed by the HBAO add-on)"
        node.hide = True
        node.location = (nodes[0].location.x, nodes[0].location.y - 520)
    if node.scene != guard:
        node.scene = guard
    for output in node.outputs:
        set_if_different(output, "hide", True)
    order = list(tree.nodes)
    managed = [n for n in order if n.bl_idname == "CompositorNodeRLayers"
               and n.get("hbao_managed")]
    return bool(managed) and order.index(managed[0]) < order.index(node)


def read_guard(main, helper):
    """(guard scene, scale) when the guard band can be used for `main`'s
    render now, else (None, why not)."""
    guard = guard_of(helper)
    if guard is None:
        return None, "its render is not set up yet (it is made when the setting changes)"
    if main.render.use_border:
        return None, "border renders have none"
    return guard, guard.get(SCALE_KEY, 1.0)
