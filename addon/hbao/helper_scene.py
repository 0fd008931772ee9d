# SPDX-License-Identifier: GPL-2.0-or-later
"""The helper scene and the managed Render Layers node: how AO computed in
Python reaches Blender's compositor.

Python cannot run per pixel inside the compositor, but Blender renders every
scene that a Render Layers node of the compositor tree points at after the
main scene's engine has finished and before compositing. So each compositor
tree that holds HBAO nodes gets a helper scene (".HBAO passes <scene>")
rendered by the add-on's engine (engine.py), and a managed, collapsed Render
Layers node pointing at it, whose outputs "HBAO <n>" are linked to each
node's hidden "HBAO Pass" input.

The helper belongs to the tree, not to a scene: from Blender 5.0 one
compositing node group may serve several scenes, and a managed node that
pointed at each scene's helper in turn would flip with every sync. The render
handlers record the scene being rendered, which the engine reads."""
import bpy

from . import (compat, compositor_effects, extra_renders, helper_render_settings, hook_release,
               node_place, pass_sources, strip_cameras, view_cameras, writes)
from .data_edits import set_if_different
from .helper_lookup import (ENGINE_IDNAME, HELPER_SCENE_PREFIX, MAIN_SCENE_KEY, MAIN_TREE_KEY,
                            MANAGED_NODE_KEY, helper_scene_of, is_helper, main_scene_of,
                            managed_node, scenes_pointing_at, scenes_served_by, serves)
from .node import AO_PASS_INPUT, DEPTH_INPUT, hbao_nodes, next_pass_index, pass_name
from .report import log
from .socket_values import upstream

MANAGED_NODE_NAME = "HBAO Passes"
# How far below the first HBAO node the managed node goes (node editor units):
# the HBAO node is about 555 units tall with its options and a hint line
# (tests/test_ui.py measures it), a status line adds about 25.
HBAO_NODE_CLEARANCE = 660
# Helper scene name -> name of the scene whose render is using it now; the
# helpers whose scene's render job runs (record_rendering .. record_render_end).
_rendering = {}
_in_progress = set()


def record_rendering(scene):
    """Called when `scene` starts rendering: its helper computes for it."""
    helper = helper_scene_of(scene)
    if helper is not None:
        _rendering[helper.name] = scene.name
        _in_progress.add(helper.name)
        helper_render_settings.copy(scene, helper)
        extra_renders.record_rendering(scene, helper)


def record_render_end(scene):
    """Called when `scene`'s render job ends (completed or cancelled)."""
    _in_progress.discard(getattr(helper_scene_of(scene), "name", None))


def any_rendering():
    """Whether a render job of a scene with a helper runs now."""
    return bool(_in_progress)


def rendered_for_a_scene(helper):
    """False when an artist renders the helper scene itself."""
    return helper.name in _in_progress


def scene_for_render(helper):
    """The scene whose render is rendering `helper` now (the last one that
    started), else the scene it was made for."""
    scene = bpy.data.scenes.get(_rendering.get(helper.name, ""))
    if scene is not None and serves(helper, scene):
        return scene
    main = main_scene_of(helper)
    if main is not None and serves(helper, main):
        return main
    served = scenes_served_by(helper)
    return served[0] if served else None


def _find_or_make_helper_scene(scene):
    """`scene`'s helper, made if it has none; and whether it is new."""
    helper = helper_scene_of(scene)
    if helper is not None:
        return helper, False
    # One made for this scene whose managed node was deleted by hand: reused,
    # so that no second helper appears beside it.
    for candidate in bpy.data.scenes:
        if (is_helper(candidate) and candidate.library is None
                and candidate.get(MAIN_SCENE_KEY) == scene.name
                and not scenes_pointing_at(candidate)):
            return candidate, True
    helper = bpy.data.scenes.new(HELPER_SCENE_PREFIX + scene.name)
    with writes.whole_or_removed(lambda: bpy.data.scenes.remove(helper)):
        helper[MAIN_SCENE_KEY] = scene.name
        # before the managed node asks it for its passes
        helper.render.engine = ENGINE_IDNAME
    log(f"created helper scene {helper.name!r} for {scene.name!r}")
    return helper, True


def _owner(helper, scene):
    """The scene whose settings the helper follows between renders: the one
    it was made for, while that one still uses it; else `scene`."""
    owner = main_scene_of(helper)
    return owner if owner is not None and serves(helper, owner) else scene


def _configure_helper_scene(scene, helper, restructured):
    """Settings, camera and objects of `helper`, once the managed node of
    `scene`'s tree points at it. `restructured`: objects linked or unlinked,
    or a new scene: it must settle before a render."""
    if compat.TREES_SHARED_BETWEEN_SCENES and (restructured or helper.get(MAIN_TREE_KEY) is None):
        # (a helper reused for its scene serves the scene's group now)
        helper[MAIN_TREE_KEY] = compat.compositor_tree(scene)
    # Between renders the helper follows one scene, the one it was made for,
    # so that syncing scenes that share its tree does not flip its settings
    # back and forth (each change would trigger another sync). A render
    # copies its own scene's settings (record_rendering).
    owner = _owner(helper, scene)
    # The name, not a pointer (see the module's text); also replaces the
    # pointer of a file saved by an older add-on, and follows a renamed scene.
    if helper.library is None and helper.get(MAIN_SCENE_KEY) != owner.name:
        helper[MAIN_SCENE_KEY] = owner.name
    set_if_different(helper.render, "engine", ENGINE_IDNAME)
    if not compat.HAS_COMPOSITING_NODE_GROUP and helper.use_nodes:
        helper.use_nodes = False
    if owner == scene:
        helper_render_settings.copy(scene, helper)
        helper_render_settings.copy_views(scene, helper)
    # The helper's render needs a camera; the main cameras themselves, so that
    # their animation is evaluated at the frame being rendered in the helper's
    # depsgraph. Every scene sharing the tree brings its own, and those that
    # sequencer strips and stereo views show it through.
    cameras = view_cameras.render_cameras(scenes_served_by(helper))
    if not cameras:  # scenes that only composite other scenes' renders
        cameras = [view_cameras.stand_in_camera(compat.compositor_tree(scene))]
    for camera in cameras:
        if helper.collection.objects.get(camera.name) != camera:
            helper.collection.objects.link(camera)
            restructured = True
    set_if_different(helper, "camera", owner.camera or cameras[0])
    for obj in list(helper.collection.objects):
        if obj not in cameras:
            helper.collection.objects.unlink(obj)
            restructured = True
    view_cameras.drop_unused_stand_in()
    if restructured:
        compat.settle_new_scene(helper)


def _ensure_managed_node(tree, nodes, helper):
    rlayers = managed_node(tree)
    if rlayers is None:
        rlayers = tree.nodes.new("CompositorNodeRLayers")
        with writes.whole_or_removed(lambda: tree.nodes.remove(rlayers)):
            rlayers[MANAGED_NODE_KEY] = True
            rlayers.name = MANAGED_NODE_NAME
            # (short enough for the collapsed node: the longer label was cut
            # before its "add-on"; a review's find)
            rlayers.label = "HBAO passes: leave in place"
            # Below the first HBAO node, clear of the artist's Render Layers
            # node on its left.
            rlayers.location = (nodes[0].location.x,
                                nodes[0].location.y - HBAO_NODE_CLEARANCE)
            rlayers.hide = True
    if rlayers.scene != helper:
        rlayers.scene = helper
    set_if_different(rlayers, "mute", False)  # as hook_release.py leaves it
    # Missing (new node) or unavailable (file loaded before the engine was
    # registered): re-assigning the layer makes Blender ask the engine for
    # its passes again.
    if any(rlayers.outputs.get(pass_name(node)) is None
           or not rlayers.outputs[pass_name(node)].enabled for node in nodes):
        rlayers.layer = helper.view_layers[0].name
    for output in rlayers.outputs:
        if not output.is_linked:
            set_if_different(output, "hide", True)
    return rlayers


def _extra_view_layer(scene, nodes):
    """The view layer whose collections the extra renders mirror: that of
    the Depth pass of the first node that asks for one."""
    for node in nodes:
        if (node.guard_band > 0.0 or node.back_faces) and not node.mute:
            source = upstream(node.inputs[DEPTH_INPUT])
            if source is not None and source.node.bl_idname == "CompositorNodeRLayers":
                return scene.view_layers.get(source.node.layer)
    return scene.view_layers[0] if len(scene.view_layers) else None


def _unhook_other_effects(scene, served):
    """5.3: the group a scene's hook serves follows its compositor effects
    (compositor_effects.py). A group served before and by no scene now
    keeps no managed Render Layers node (it rendered a helper that serves
    another group), and its HBAO nodes pass Image through."""
    for effect in getattr(scene, "compositor_effects", ()):
        group = effect.node_group
        rlayers = managed_node(group) if group is not None and group != served else None
        if rlayers is None or any(compat.compositor_tree(other) == group
                                  for other in bpy.data.scenes):
            continue
        hook_release.unlink_ao_inputs(group)
        group.nodes.remove(rlayers)
        log(f"removed the HBAO hook of compositor effect {effect.name!r} of {scene.name!r}")


def sync(scene, rendering=False):
    """Create, update or remove the hook of `scene` to match its HBAO nodes.
    Main thread only (`rendering`: in a render's start handlers, where the
    extra renders' scenes stay until the render has ended); returns a list
    of messages."""
    tree = compat.compositor_tree(scene)
    if tree is None or is_helper(scene) or node_place.unhooked(scene, tree):
        return []  # (the nodes of a linked tree say why they get no AO)
    _unhook_other_effects(scene, tree)
    nodes = hbao_nodes(tree)
    if not nodes:
        # found through the managed node: before it goes
        helper = helper_scene_of(scene)
        if helper is not None:
            extra_renders.remove_all(helper, tree)
        rlayers = managed_node(tree)
        if rlayers is not None:
            tree.nodes.remove(rlayers)
            log(f"removed the HBAO hook of {scene.name!r} (no HBAO node left)")
        if helper is not None:
            bpy.data.scenes.remove(helper)
            view_cameras.drop_unused_stand_in()
        return []

    messages = pass_sources.enable_needed_passes(scene, tree)
    seen = set()
    for node in nodes:
        if node.pass_index == 0 or node.pass_index in seen:
            node.pass_index = next_pass_index(tree, exclude=node)
        seen.add(node.pass_index)

    helper, new = _find_or_make_helper_scene(scene)
    if extra_renders.sync(scene, tree, nodes, helper, _extra_view_layer(scene, nodes),
                          rendering):
        # made again below, after the guard's node: Blender renders in node order
        tree.nodes.remove(managed_node(tree))
    rlayers = _ensure_managed_node(tree, nodes, helper)
    _configure_helper_scene(scene, helper, new)
    # By the owner's setting, as the helper's settings: scenes that share the
    # tree (5.x) and differ would flip the links at each sync, and each flip
    # schedules another.
    linked = helper_render_settings.helper_renders(_owner(helper, scene))
    for node in nodes:
        output = rlayers.outputs.get(pass_name(node))
        target = node.inputs.get(AO_PASS_INPUT)
        if output is None or target is None:
            messages.append(f"node {node.name!r}: its AO pass socket is not available yet")
            continue
        if not linked:  # AO 1: the node passes Image through
            hook_release.unlink_ao_input(tree, node)
            continue
        # Blender unhides linked sockets and refuses to hide them, so this one
        # link stays visible; the collapsed Render Layers node shows only it.
        if not (target.is_linked and target.links[0].from_socket == output):
            for link in list(output.links):
                tree.links.remove(link)
            tree.links.new(output, target)
    return messages


def sync_all():
    """sync() every scene with HBAO nodes or a hook; drop helpers nobody uses.
    Returns whether Blender refused a write for the moment
    (writes.writes_refused): a later call finishes the job. Helpers first:
    the extra scenes of one dropped go in the same pass (a save then)."""
    with strip_cameras.walking_strips_once(), compositor_effects.reading_each_scene_once():
        for scene in sorted(bpy.data.scenes, key=lambda scene: not is_helper(scene)):
            try:
                _sync_or_drop(scene)
            except Exception as error:  # never break the user's session
                if writes.writes_refused(error):
                    return True  # the rest waits too
                log(f"could not update the HBAO hook of {scene.name!r}: {error}")
    return False


def _sync_or_drop(scene):
    if extra_renders.is_extra(scene):
        if not any(extra_renders.scene_of(helper, kind) == scene
                   for helper in bpy.data.scenes if is_helper(helper)
                   for kind in extra_renders.KINDS):
            bpy.data.scenes.remove(scene)
    elif is_helper(scene):
        if not scenes_served_by(scene):
            bpy.data.scenes.remove(scene)
            view_cameras.drop_unused_stand_in()
    else:
        tree = compat.compositor_tree(scene)
        if hbao_nodes(tree) or managed_node(tree) is not None:
            sync(scene)
