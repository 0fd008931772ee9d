# SPDX-License-Identifier: GPL-2.0-or-later
"""Which node group of a scene's compositor the add-on serves. Blender 5.3
composites a stack of effects (`scene.compositor_effects`), each a node
group run on the one before's image; `scene.compositing_node_group` is the
active effect's group only (and deprecated). The add-on serves one group a
scene: the first effect's, among those enabled for renders, whose group
holds an HBAO node at its top level; else the first such effect's, enabled
or not; else the active effect's (where a new node goes). Measured in bpy 5.3: with
the active one served, adding a second effect after the HBAO one (Add
Effect makes it active) left the HBAO node unserved and its render black.
Reads only the scene given: no bpy import."""
import contextlib

# The HBAO node's type name (node.py registers the node): here, below every
# module that looks for HBAO nodes.
NODE_IDNAME = "CompositorNodeHBAO"


def is_hbao_node(node):
    return getattr(node, "bl_idname", "") == NODE_IDNAME


def holds_hbao_node(tree):
    """Whether node tree `tree` (or None) has an HBAO node at its top level."""
    return tree is not None and any(is_hbao_node(node) for node in tree.nodes)


def served_effect(scene):
    """The effect of 5.3's stack whose group the add-on serves, or None:
    none there, or a Blender without the stack."""
    effects = getattr(scene, "compositor_effects", None)
    if effects is None:
        return None
    first_holding = None  # (read up to the first enabled one only: draws and handlers ask)
    for effect in effects:
        if holds_hbao_node(effect.node_group):
            if effect.enable_for_render:
                return effect
            first_holding = first_holding or effect
    return first_holding or effects.active


# While a sync reads every scene (reading_each_scene_once): {a scene's
# session_uid: the group served_group() found}; None otherwise.
_served_groups = None


@contextlib.contextmanager
def reading_each_scene_once():
    """Inside, served_group() reads each scene's stack of effects once: a
    sync asks every scene for its group once per helper scene
    (helper_lookup.scenes_served_by), and in 5.3 each ask walks the effects'
    nodes (58 % of a 0.44 s sync of a 100-scene file, bench/addon_sync.py).
    A sync adds no HBAO node and changes no effect's switches, and
    set_served_group forgets the scene it sets. Keyed by session_uid, which
    Blender never gives twice (a scene made after another was removed may
    take its address)."""
    global _served_groups
    outer = _served_groups  # (inside another: its reads serve)
    _served_groups = outer if outer is not None else {}
    try:
        yield
    finally:
        _served_groups = outer


def served_group(scene):
    """The compositing node group of `scene` (5.0 and later) that the add-on
    serves, or None."""
    if getattr(scene, "compositor_effects", None) is None:
        return getattr(scene, "compositing_node_group", None)
    key = getattr(scene, "session_uid", None) if _served_groups is not None else None
    if key is not None and key in _served_groups:
        return _served_groups[key]
    effect = served_effect(scene)
    group = effect.node_group if effect is not None else None
    if key is not None:
        _served_groups[key] = group
    return group


def set_served_group(scene, tree):
    """Make node group `tree` the compositor of `scene` (5.0 and later): in
    5.3 the active effect's group (a new effect where the stack is empty),
    what the deprecated `scene.compositing_node_group` does when set; in 5.0
    that property."""
    effects = getattr(scene, "compositor_effects", None)
    if effects is None:
        scene.compositing_node_group = tree
        return
    effect = effects.active
    if effect is None:  # (named as Blender names it: "Scene Effect")
        effect = effects.new(name="")
    effect.node_group = tree
    if _served_groups is not None:
        _served_groups.pop(getattr(scene, "session_uid", None), None)


def other_effect_holding(scene, tree):
    """The effect of `scene`'s stack whose group is `tree` where the add-on
    serves another one, or None."""
    served = served_group(scene)
    for effect in getattr(scene, "compositor_effects", ()):
        if effect.node_group == tree and tree != served:
            return effect
    return None


def off_for_renders(scene):
    """The served effect where it is switched off for renders (5.3's
    Enable for Render), or None."""
    effect = served_effect(scene)
    return effect if effect is not None and not effect.enable_for_render else None
