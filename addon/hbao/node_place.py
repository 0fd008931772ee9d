# SPDX-License-Identifier: GPL-2.0-or-later
"""Where an HBAO node lies: in a scene's compositor tree itself, where the
render hook computes its AO, or inside a node group of the artist's, where
the hook does not reach it (its Depth and Normal come through the group's
sockets, and one group may serve several places). Such a node passes Image
through, and the node and the render say so."""
from . import compat

GROUPED_SHORT = "In a node group: AO off"
GROUPED_DETAILS = ("HBAO works only at the top level of a scene's compositor, not inside a node "
                   "group: this node passes Image through and its AO is white. Ungroup it "
                   "(Ctrl+Alt+G) or move it to the top level")


def at_top_level(node):
    """Whether `node` lies in a scene's compositor tree itself."""
    return compat.scene_of_tree(node.id_data) is not None


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
