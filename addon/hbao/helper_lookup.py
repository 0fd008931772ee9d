# SPDX-License-Identifier: GPL-2.0-or-later
"""Which helper scene serves which of the artist's scenes: the add-on's marks
on its helper scenes and managed nodes, and the lookups both ways.

Nothing points from the helper at the user's scene (an ID pointer would
count as one more user of the scene in Blender's scene selector): the
helper's scene is the one whose managed node points at the helper; the
helper keeps that scene's name only to choose between several such scenes
(a scene copied with its tree)."""
import bpy

from . import compat
from .node import hbao_nodes, pass_name

ENGINE_IDNAME = "HBAO_PASSES"
HELPER_SCENE_PREFIX = ".HBAO passes "
# ID property on the helper scene: the name of the scene it was made for
# (files saved by the add-on before this change hold a pointer instead).
MAIN_SCENE_KEY = "hbao_main_scene"
# ID property on the helper scene (5.0+): the compositing node group it serves.
MAIN_TREE_KEY = "hbao_main_tree"
# ID property on the Render Layers node the add-on manages.
MANAGED_NODE_KEY = "hbao_managed"

# Every lookup here runs for each scene at each sync (after every edit) and
# at the nodes' timer, so a helper's scene is looked for by the name the
# helper keeps first, and the file walked only where that fails: walking
# every scene's tree for every pair of scenes made a sync of a 40-scene file
# take 390 ms (bench/addon_sync.py).


def managed_node(tree):
    """The first Render Layers node of `tree` that the add-on manages."""
    if tree is None:
        return None
    for node in tree.nodes:
        if node.bl_idname == "CompositorNodeRLayers" and node.get(MANAGED_NODE_KEY):
            return node
    return None


def is_helper(scene):
    # The key stays when the scene it names is deleted (its value becomes None).
    return MAIN_SCENE_KEY in scene.keys()


def _points_at(scene, helper):
    """Whether the user's `scene` has a managed node pointing at `helper`."""
    if is_helper(scene):
        return False
    node = managed_node(compat.compositor_tree(scene))
    return node is not None and node.scene == helper


def scenes_pointing_at(helper):
    """The user's scenes whose managed node points at `helper`."""
    return [scene for scene in bpy.data.scenes if _points_at(scene, helper)]


def main_scene_of(helper):
    """The scene `helper` was made for, or None (not a helper, or deleted):
    of the scenes whose managed node points at it, the one of the name it
    keeps, else the first (the scene was renamed)."""
    if not is_helper(helper):
        return None
    kept = helper.get(MAIN_SCENE_KEY)
    if isinstance(kept, bpy.types.Scene):  # a file saved by an older add-on
        return kept
    named = bpy.data.scenes.get(kept) if isinstance(kept, str) else None
    if named is not None and _points_at(named, helper):
        return named
    candidates = scenes_pointing_at(helper)
    for scene in candidates:
        if scene.name == kept:
            return scene
    return candidates[0] if candidates else None


def tree_of_helper(helper):
    """The compositor tree whose HBAO nodes the helper serves."""
    tree = helper.get(MAIN_TREE_KEY) if compat.TREES_SHARED_BETWEEN_SCENES else None
    if isinstance(tree, bpy.types.NodeTree):
        return tree
    main = main_scene_of(helper)
    return compat.compositor_tree(main) if main is not None else None


def serves(helper, scene):
    """Whether `helper` publishes the AO of `scene`'s compositor tree. A
    helper linked from another file serves that file's scenes only (a scene
    of this file that composites with a linked tree gets no AO:
    node_place.unhooked)."""
    if not is_helper(helper) or not _may_serve(helper, scene):
        return False
    tree = compat.compositor_tree(scene)
    return tree is not None and tree_of_helper(helper) == tree


def _may_serve(helper, scene):
    """serves() before the trees are compared: `scene` is the user's, and
    of the helper's file where the helper is linked."""
    return not is_helper(scene) and (helper.library is None or scene.library is not None)


def helper_scene_of(scene):
    node = managed_node(compat.compositor_tree(scene))
    if node is not None and node.scene is not None and serves(node.scene, scene):
        return node.scene
    for candidate in bpy.data.scenes:
        if serves(candidate, scene):
            return candidate
    return None


def scenes_served_by(helper):
    if not is_helper(helper):
        return []
    helper_tree = tree_of_helper(helper)  # (once, not once a scene)
    return [scene for scene in bpy.data.scenes if helper_tree is not None
            and _may_serve(helper, scene) and compat.compositor_tree(scene) == helper_tree]


def pass_names_for_helper(helper):
    """The AO passes the helper scene's engine publishes (one per HBAO node)."""
    return [pass_name(node) for node in hbao_nodes(tree_of_helper(helper))]
