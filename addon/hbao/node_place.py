# SPDX-License-Identifier: GPL-2.0-or-later
"""Where an HBAO node lies: in a scene's compositor tree itself, where the
render hook computes its AO, or inside a node group of the artist's, where
the hook does not reach it (its Depth and Normal come through the group's
sockets, and one group may serve several places), or in a compositor effect
(5.3) other than the one the add-on serves, or in a sequencer strip's
compositor (strip_groups.py), or in a tree linked from another file, which
the hook cannot be added to. Such a node passes Image through, and the node
and the render say so."""
import bpy

from . import compat, compositor_effects, strip_groups
from .compositor_effects import is_hbao_node

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
STRIP_SHORT = "In a strip's compositor: AO off"
STRIP_DETAILS = ("HBAO works in a scene's compositor, not in a sequencer strip's Compositor "
                 "modifier or a Compositor strip, which have no render passes: this node passes "
                 "Image through and its AO is white. Put it in the compositor of the scene that "
                 "the strip shows")
LINKED_SHORT = "In a linked tree: AO off"
LINKED_DETAILS = ("This compositor node tree comes from another file ({source}), and the add-on "
                  "cannot add its render hook to it: this node passes Image through and its AO "
                  "is white. Make the tree local (Make Local, or File > Append instead of Link)")


def from_another_file(tree):
    """Whether node tree `tree` is linked from a library or overridden:
    the add-on does not edit it."""
    return tree is not None and (tree.library is not None
                                 or getattr(tree, "override_library", None) is not None)


def unhooked(scene, tree):
    """Whether `scene` (of this file) composites with `tree` from another
    file, whose hook, if any, serves the other file's scene. A scene linked
    with its tree brings its hook along."""
    return scene.library is None and from_another_file(tree)


def _used_unhooked(tree):
    return any(unhooked(scene, tree) and compat.compositor_tree(scene) == tree
               for scene in bpy.data.scenes)


def _linked_details(tree):
    source = tree.library.filepath if tree.library is not None else "a library override"
    return LINKED_DETAILS.format(source=source)


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
    tree = node.id_data
    if _used_unhooked(tree):
        return LINKED_SHORT, _linked_details(tree)
    if at_top_level(node):
        return None
    for scene in bpy.data.scenes:
        if compositor_effects.other_effect_holding(scene, tree) is not None:
            served = compositor_effects.served_effect(scene)
            return OTHER_EFFECT_SHORT, OTHER_EFFECT_DETAILS.format(served=served.name)
    # (a group inside another tree first: the node draws this, and walking a
    # long sequencer's strips took 7.6 ms for 2000 strips)
    if not _used_as_a_group(tree) and any(
            tree in _trees_within(group) for scene in bpy.data.scenes
            for _strip, group in strip_groups.groups_of(scene)):
        return STRIP_SHORT, STRIP_DETAILS
    return GROUPED_SHORT, GROUPED_DETAILS


def _used_as_a_group(tree):
    hosts = list(bpy.data.node_groups) + [compat.compositor_tree(s) for s in bpy.data.scenes]
    return any(getattr(member, "node_tree", None) == tree
               for host in hosts if host is not None for member in host.nodes)


def render_messages(scene):
    """What a render of `scene` says about its HBAO nodes that get no AO
    where they lie, as report.NodeMessage reads: after "HBAO " in Blender's
    reports."""
    tree = compat.compositor_tree(scene)
    messages = []
    if unhooked(scene, tree):
        messages += [f'node "{node.name}" in linked tree "{tree.name}": {_linked_details(tree)}'
                     for node in tree.nodes if is_hbao_node(node)]
    messages += [grouped_message(group, grouped) for group, grouped in nodes_in_groups(tree)]
    messages += other_effect_messages(scene)
    return messages + [
        f'node "{node.name}" in the compositor of strip "{strip.name}": {STRIP_DETAILS}'
        for strip, group in strip_groups.groups_of(scene, rendered=True)
        for within in _trees_within(group)
        for node in within.nodes if is_hbao_node(node)]


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
            for node in effect.node_group.nodes if is_hbao_node(node)]


def _trees_within(tree):
    """`tree` and the node groups it uses, at any depth, each once; an HBAO
    node's own group (the add-on's) is not entered."""
    seen, pending = ({tree.as_pointer()}, [tree]) if tree else (set(), [])
    while pending:
        current = pending.pop()
        yield current
        for member in current.nodes:
            group = getattr(member, "node_tree", None)
            if not is_hbao_node(member) and group is not None \
                    and group.as_pointer() not in seen:
                seen.add(group.as_pointer())
                pending.append(group)


def nodes_in_groups(tree):
    """[(group tree, node)]: the HBAO nodes inside the node groups that
    `tree` uses, at any depth."""
    return [(within, member) for within in _trees_within(tree) if within != tree
            for member in within.nodes if is_hbao_node(member)]


def grouped_message(group, node):
    """What a render says about `node` inside node group `group`, as
    report.NodeMessage reads: after "HBAO " in Blender's reports."""
    return f'node "{node.name}" in node group "{group.name}": {GROUPED_DETAILS}'
