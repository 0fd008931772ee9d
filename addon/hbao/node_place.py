# SPDX-License-Identifier: GPL-2.0-or-later
"""Where an HBAO node lies: in a scene's compositor tree itself, where the
render hook computes its AO, or inside a node group of the artist's, where
the hook does not reach it (its Depth and Normal come through the group's
sockets, and one group may serve several places), or in a compositor effect
(5.3) other than the one the add-on serves. Such a node passes Image
through, and the node and the render say so."""
import bpy

from . import compat, compositor_effects

GROUPED_SHORT = "In a node group: AO off"
GROUPED_DETAILS = ("HBAO works only at the top level of a scene's compositor, not inside a node "
                   "group: this node passes Image through and its AO is white. Ungroup it "
                   "(Ctrl+Alt+G) or move it to the top level")
# Blender 5.3's stack of compositor effects (compositor_effects.py)
OTHER_EFFECT_SHORT = "In another effect: AO off"
OTHER_EFFECT_DETAILS = ("HBAO works in one compositor effect of a scene, the first enabled for "
                        "renders whose node group holds an HBAO node (\"{served}\"): this node "
                        "passes Image through and its AO is white. Move it into that effect's "
                        "group")


def at_top_level(node):
    """Whether `node` lies in a scene's compositor tree itself (the node
    draws from it: only the scenes whose effects hold its tree are read)."""
    tree = node.id_data
    for scene in bpy.data.scenes:
        effects = getattr(scene, "compositor_effects", None)
        if effects is None:
            if compat.compositor_tree(scene) == tree:
                return True
        elif any(effect.node_group == tree for effect in effects) and \
                compositor_effects.served_group(scene) == tree:
            return True
    return False


def misplaced(node):
    """(short, details) of why `node` gets no AO where it lies, or None."""
    if at_top_level(node):
        return None
    for scene in bpy.data.scenes:
        if compositor_effects.other_effect_holding(scene, node.id_data) is not None:
            served = compositor_effects.served_effect(scene)
            return OTHER_EFFECT_SHORT, OTHER_EFFECT_DETAILS.format(served=served.name)
    return GROUPED_SHORT, GROUPED_DETAILS


def other_effect_messages(scene):
    """What a render of `scene` says about the HBAO nodes of the effects
    (5.3) whose group the add-on does not serve, as report.NodeMessage
    reads: after "HBAO " in Blender's reports."""
    served = compositor_effects.served_effect(scene)
    if served is None:  # (no effect holds an HBAO node, and none is active)
        return []
    return [f'node "{node.name}" in compositor effect "{effect.name}": '
            + OTHER_EFFECT_DETAILS.format(served=served.name)
            for effect in getattr(scene, "compositor_effects", ())
            if effect.node_group is not None and effect.node_group != served.node_group
            for node in effect.node_group.nodes if compositor_effects.is_hbao_node(node)]


def nodes_in_groups(tree, wanted):
    """[(group tree, node)]: the nodes for which `wanted(node)` is true inside
    the node groups that `tree` uses, at any depth; a wanted node's own
    group (the HBAO node's is the add-on's) is not searched."""
    found, seen, pending = [], set(), [tree] if tree else []
    while pending:
        current = pending.pop()
        for member in current.nodes:
            if wanted(member):
                if current != tree:
                    found.append((current, member))
                continue
            group = getattr(member, "node_tree", None)
            if group is not None and group.as_pointer() not in seen:
                seen.add(group.as_pointer())
                pending.append(group)
    return found


def grouped_message(group, node):
    """What a render says about `node` inside node group `group`, as
    report.NodeMessage reads: after "HBAO " in Blender's reports."""
    return f'node "{node.name}" in node group "{group.name}": {GROUPED_DETAILS}'
