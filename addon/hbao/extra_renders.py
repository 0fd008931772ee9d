# SPDX-License-Identifier: GPL-2.0-or-later
"""The extra renders a node may ask for, each a hidden scene that holds the
artist's collections (linked, not copied), rendered by Cycles at 1 sample,
with a managed Render Layers node pointing at it: the guard band
(guard_geometry.py), a camera that follows the scene camera with a view
widened about the frame's centre, Depth and Normal; the back faces, the scene
camera and a material override that makes front faces transparent, so that
Cycles writes the Depth of the first back face behind the visible surface
(it writes data passes only at surfaces at least as opaque as the view
layer's alpha threshold).

Blender renders the scenes of a compositor tree's Render Layers nodes in the
order of the tree's nodes, at the main render's size, so these nodes come
before the helper's: when the helper's engine runs, their Render Results
hold this frame's passes (docs/blender-integration.md)."""
import bpy

from . import back_material, camera_time, compat, guard_camera, guard_geometry, \
    helper_render_settings, strip_cameras, writes
from .camera import CameraError
from .data_edits import set_if_different
from .report import log


class Kind:
    """What tells one extra render from the other."""

    def __init__(self, name, prefix, helper_key, node_key, node_name, wants_normal):
        self.name = name
        self.prefix = prefix
        self.helper_key = helper_key  # ID property on the helper: its scene
        self.node_key = node_key      # ID property on its Render Layers node
        self.node_name = node_name
        self.wants_normal = wants_normal


GUARD = Kind("guard band", ".HBAO guard band ", "hbao_guard_scene", "hbao_guard_node",
             "HBAO Guard Band", True)
BACK = Kind("back faces", ".HBAO back faces ", "hbao_back_scene", "hbao_back_node",
            "HBAO Back Faces", False)
KINDS = (GUARD, BACK)
# ID property on an extra scene: it is one (the helper's name, for people).
EXTRA_KEY = "hbao_guard_for"
# ID property on the guard scene: how much wider its camera sees.
SCALE_KEY = "hbao_guard_scale"


def is_extra(scene):
    return EXTRA_KEY in scene.keys()


def scene_of(helper, kind):
    scene = helper.get(kind.helper_key) if helper is not None else None
    return scene if isinstance(scene, bpy.types.Scene) else None


def wanted_fraction(nodes):
    """The widest band the tree's unmuted HBAO nodes ask for (fraction)."""
    return max([node.guard_band / 100.0 for node in nodes if not node.mute] or [0.0])


def _wanted(kind, nodes):
    if kind is GUARD:
        return wanted_fraction(nodes) > 0.0
    return any(node.back_faces for node in nodes if not node.mute)


def node_of(tree, kind):
    if tree is None:
        return None
    for node in tree.nodes:
        if node.bl_idname == "CompositorNodeRLayers" and node.get(kind.node_key):
            return node
    return None


# --- shared -------------------------------------------------------------------

def _configure_render(scene, kind):
    render = scene.render
    set_if_different(render, "engine", "CYCLES")
    cycles = getattr(scene, "cycles", None)
    if cycles is not None:
        for name, value in (("samples", 1), ("use_denoising", False),
                            ("use_adaptive_sampling", False), ("max_bounces", 0),
                            ("transparent_max_bounces", 64), ("filter_width", 0.01)):
            if hasattr(cycles, name):
                set_if_different(cycles, name, value)
    set_if_different(render, "use_motion_blur", False)
    settings = render.image_settings
    if settings.file_format != "OPEN_EXR_MULTILAYER":
        compat.set_multilayer_exr(settings)
        settings.color_depth = "32"
        settings.exr_codec = "NONE"
    view_layer = scene.view_layers[0]
    set_if_different(view_layer, "use_pass_z", True)
    set_if_different(view_layer, "use_pass_normal", kind.wants_normal)
    if kind is BACK:
        if view_layer.material_override is None:
            view_layer.material_override = back_material.get_or_make()
        set_if_different(view_layer, "pass_alpha_threshold", 0.5)
    if not compat.HAS_COMPOSITING_NODE_GROUP and scene.use_nodes:
        scene.use_nodes = False


def _link_exactly(links, wanted):
    """Link each of `wanted` into `links` (a collection's children or
    objects) and unlink the rest; returns whether anything changed."""
    changed = False
    for item in wanted:
        if links.get(item.name) != item:
            links.link(item)
            changed = True
    for item in list(links):
        if item not in wanted:
            links.unlink(item)
            changed = True
    return changed


def _link_contents(main, scene, extra_objects):
    """The artist's collections and loose objects, linked; nothing else.
    Returns whether anything was linked or unlinked."""
    collections = _link_exactly(scene.collection.children, list(main.collection.children))
    objects = _link_exactly(scene.collection.objects,
                            list(main.collection.objects) + extra_objects)
    return collections or objects


def _mirror_exclusions(source, target):
    """The extra scene's view layer leaves out what the node's view layer does."""
    by_collection = {child.collection: child for child in target.children}
    for child in source.children:
        mirror = by_collection.get(child.collection)
        if mirror is not None:
            set_if_different(mirror, "exclude", child.exclude)
            _mirror_exclusions(child, mirror)


def remove(helper, tree, kind, keep_scene=False):
    """Remove `helper`'s extra render of `kind`: its node, and its scene
    unless `keep_scene` (a render is starting: bpy 5.3 crashed, in
    render_init_depsgraph, rendering a frame whose render_init handler had
    removed one; the next sync after every render job has ended removes it:
    handlers.py)."""
    node = node_of(tree, kind)
    if node is not None:
        tree.nodes.remove(node)
    scene = scene_of(helper, kind)
    if scene is None or keep_scene:
        return
    camera = scene.camera if kind is GUARD else None
    del helper[kind.helper_key]
    bpy.data.scenes.remove(scene)
    if camera is not None and camera.users == 0:
        data = camera.data
        bpy.data.objects.remove(camera)
        if data is not None and data.users == 0:
            bpy.data.cameras.remove(data)
    if kind is BACK:
        back_material.remove_if_unused()
    log(f"removed the {kind.name} render of {helper.name!r}")


def remove_all(helper, tree):
    for kind in KINDS:
        remove(helper, tree, kind)


def _sync_kind(main, tree, nodes, helper, view_layer, kind):
    """Create or update the extra scene and node of `kind`; returns the node."""
    scene = scene_of(helper, kind)
    if scene is None:
        scene = bpy.data.scenes.new(kind.prefix + main.name)
        with writes.whole_or_removed(lambda: bpy.data.scenes.remove(scene)):
            scene[EXTRA_KEY] = helper.name
            helper[kind.helper_key] = scene
        log(f"created the {kind.name} render {scene.name!r} for {main.name!r}")
    _configure_render(scene, kind)
    if kind is GUARD:
        scale = guard_geometry.guard_scale(wanted_fraction(nodes))
        if scene.get(SCALE_KEY) != scale:
            scene[SCALE_KEY] = scale
        extra_objects = [guard_camera.follow(main, scene, GUARD.prefix + main.name)]
    else:
        if scene.camera != main.camera:
            scene.camera = main.camera
        extra_objects = []
    layers = scene.view_layers[0]
    if _link_contents(main, scene, extra_objects) or layers.layer_collection is None:
        # 5.3 syncs a new scene's layer collections only when asked
        compat.settle_new_scene(scene)
    if view_layer is not None and layers.layer_collection is not None:
        _mirror_exclusions(view_layer.layer_collection, layers.layer_collection)
    if kind is GUARD:
        guard_camera.copy_settings(main, scene, scene.get(SCALE_KEY, 1.0))
    node = node_of(tree, kind)
    if node is None:
        node = tree.nodes.new("CompositorNodeRLayers")
        with writes.whole_or_removed(lambda: tree.nodes.remove(node)):
            node[kind.node_key] = True
            node.name = kind.node_name
            node.label = f"{kind.node_name}: leave in place"
            node.hide = True
            node.location = (nodes[0].location.x,
                             nodes[0].location.y - 520 - 40 * KINDS.index(kind))
    if node.scene != scene:
        node.scene = scene
    for output in node.outputs:
        set_if_different(output, "hide", True)
    return node


def sync(main, tree, nodes, helper, view_layer, rendering=False):
    """Create, update or remove the extra renders of `helper` for `main`'s
    HBAO nodes; `view_layer` is the one whose collections they mirror. Main
    thread only; `rendering`: at a render's start (remove keeps the scenes).
    Returns True when the helper's managed node must be made again, after
    theirs (render order)."""
    extra_nodes = []
    for kind in KINDS:
        if main.camera is None or main.render.use_multiview or not _wanted(kind, nodes):
            remove(helper, tree, kind, keep_scene=rendering)
        else:
            extra_nodes.append(_sync_kind(main, tree, nodes, helper, view_layer, kind))
    order = list(tree.nodes)
    managed = [n for n in order if n.bl_idname == "CompositorNodeRLayers"
               and n.get("hbao_managed")]
    return bool(managed) and any(order.index(managed[0]) < order.index(node)
                                 for node in extra_nodes)


def _left_out(main):
    """Why `main`'s render cannot use the extra renders now, or None. They
    follow the scene camera at the whole frame (Blender renders them there)."""
    if main.render.use_border:
        return "border renders have none"
    if main.render.use_multiview:  # (sync removes their scenes)
        return "stereo and multi-view renders have none"
    if camera_time.of(main) != main.frame_current:
        return ("the passes show the camera at another time than the frame (a subframe, or "
                "motion blur's shutter Start or End)")
    try:
        if strip_cameras.override_for(main) is not None:
            return "a Video Sequencer strip renders the scene through another camera"
    except CameraError:  # (two strips, two cameras: the AO is off, and says why)
        return "Video Sequencer strips render the scene through other cameras"
    return None


def record_rendering(main, helper):
    """At the start of `main`'s render and of its frames (any thread): the
    guard camera follows the scene camera (maybe animated); an extra scene
    whose render the frame cannot use has its view layer off (a plain
    setting), so Blender does not render it (about 0.3 s a frame each)."""
    wanted = _left_out(main) is None
    for kind in KINDS:
        scene = scene_of(helper, kind)
        if scene is not None:
            set_if_different(scene.view_layers[0], "use", wanted)
            helper_render_settings.keep_compositor_on_cpu(scene)
    guard = scene_of(helper, GUARD)
    if guard is not None:
        guard_camera.copy_settings(main, guard, guard.get(SCALE_KEY, 1.0))


def for_render(main, helper, kind):
    """(the extra scene, None) when its render can be used for `main`'s
    render now, else (None, why not)."""
    reason = _left_out(main)
    if reason is not None:
        return None, reason
    scene = scene_of(helper, kind)
    if scene is None:
        return None, "its render is not set up yet (it is made when the setting changes)"
    if not scene.view_layers[0].use:  # record_rendering did not run: its result is stale
        return None, "its render did not run for this frame"
    return scene, None
