# SPDX-License-Identifier: GPL-2.0-or-later
"""The group tree every HBAO node shares, in a file: created, rebuilt when
a file saved with an older layout (group_layout.py) is opened, and given to
nodes that came with a copy of their own (append, paste), each node keeping
its values, links and keyframes through the change."""
import json

import bpy

from . import compat, group_layout, node_place, socket_keys
from .group_layout import AO_PASS_INPUT, GROUP_TREE_NAME


def _users(tree):
    """The group nodes that use `tree`, in the scenes' compositor trees and
    in every local compositor node group (an artist's; 5.3's effects)."""
    trees = {other.as_pointer(): other for other in bpy.data.node_groups
             if other.bl_idname == "CompositorNodeTree" and other != tree}
    trees.update((other.as_pointer(), other)
                 for other in map(compat.compositor_tree, bpy.data.scenes) if other is not None)
    return [node for other in trees.values() if other.library is None for node in other.nodes
            if getattr(node, "node_tree", None) == tree]


def _socket_state(socket):
    """What rebuilding the group's interface would lose: the socket's value,
    its links' sources (node name, output index), its keyframes (socket_keys)."""
    value = socket.default_value
    value = tuple(value) if hasattr(value, "__len__") else value
    sources = [(link.from_node.name, list(link.from_node.outputs).index(link.from_socket))
               for link in socket.links]
    return value, sources, socket_keys.saved(socket)


def _output_links(node):
    """Where the node's outputs go: (output name, to node name, to input index)."""
    return [(socket.name, link.to_node.name, list(link.to_node.inputs).index(link.to_socket))
            for socket in node.outputs for link in socket.links]


def _node_state(node):
    """What _restore needs to give `node` its values and links again."""
    return {socket.name: _socket_state(socket) for socket in node.inputs}, _output_links(node)


def _socket_of(tree, node_name, sockets, index):
    """tree.nodes[node_name].<sockets>[index], or None where that node or
    socket is gone (a restore finished later, after an edit)."""
    other = tree.nodes.get(node_name)
    collection = getattr(other, sockets, ())
    return collection[index] if other is not None and 0 <= index < len(collection) else None


def _restore(node, states, targets):
    tree = node.id_data
    for output_name, to_name, index in targets:
        output = node.outputs.get(output_name)
        target = _socket_of(tree, to_name, "inputs", index)
        if output is not None and target is not None:
            tree.links.new(output, target)
    for name, (value, sources, *keys) in states.items():
        socket = node.inputs.get(name)
        if socket is None:
            continue
        try:
            socket_keys.restore(socket, keys[0] if keys else [])
        except (TypeError, ValueError, RuntimeError):
            pass  # keys of a socket whose kind changed: its value below
        try:
            # (the pass input's value is the layout's, not the artist's: a
            # group of layout 4 held 1, which is now full occlusion; Blender
            # keeps it when an appended node moves to the shared group)
            socket.default_value = (
                group_layout.no_ao_value(node) if name == AO_PASS_INPUT
                else int(round(value)) if isinstance(socket.default_value, int) else value)
        except (TypeError, ValueError):
            pass  # a socket whose kind changed beyond a number: keep its default
        for from_name, index in sources:
            source = _socket_of(tree, from_name, "outputs", index)
            if source is not None:
                tree.links.new(source, socket)


# A node's values and links, kept on the node (an ID property) while its group
# changes: a restore Blender refuses midway (writes.py) ends at the next sync.
PENDING_KEY = "hbao_pending_restore"


def _keep_state(node):
    if PENDING_KEY not in node:  # (an unfinished one is the older, right state)
        node[PENDING_KEY] = json.dumps(_node_state(node))


def keep_copied_values(node, original):
    """A copy keeps the original's input values until it has the shared
    group (adopt_group_copies): pasted into another file, a node comes
    without its group, sockets and values. No links, no keyframes. Reads
    only the original's sockets: the clipboard's node may point at a group
    of a file since closed."""
    if PENDING_KEY in node:  # (the original's unfinished restore came along)
        return
    states = {}
    for socket in original.inputs:
        value = getattr(socket, "default_value", None)
        if value is not None:
            states[socket.name] = (tuple(value) if hasattr(value, "__len__") else value, [], {})
    node[PENDING_KEY] = json.dumps([states, []])


def _finish_restores(nodes):
    """The pending restores of `nodes` whose group is whole: not outdated or
    half rebuilt (refused midway: upgrade_group_tree finishes it first), nor
    missing (pasted from another file: adopt_group_copies gives one)."""
    for node in nodes:
        if PENDING_KEY not in node:
            continue
        tree = node.node_tree
        if tree is None or (tree.name == GROUP_TREE_NAME and not group_layout.is_current(tree)):
            continue
        try:
            states, targets = json.loads(node[PENDING_KEY])
            if not isinstance(states, dict) or not isinstance(targets, list):
                raise ValueError("not a node state")
        except (TypeError, ValueError):  # not this add-on's state: nothing to restore
            states, targets = {}, []
        _restore(node, states, targets)
        del node[PENDING_KEY]


def upgrade_group_tree():
    """Rebuild an outdated shared group in place (same name, same socket
    order, so keyframes stay on their sockets), keeping each node's values and
    links. Called after a file is loaded, and before groups are adopted."""
    tree = bpy.data.node_groups.get(GROUP_TREE_NAME)
    if tree is None or tree.library is not None:
        return
    if group_layout.is_current(tree):
        if group_layout.BUILT_KEY not in tree:  # built before the fingerprint was kept
            tree[group_layout.BUILT_KEY] = group_layout.fingerprint(tree)
        return  # (a restore left pending on a whole group: adopt_group_copies, every sync)
    users = _users(tree)
    for node in users:
        _keep_state(node)
    group_layout.build(tree)
    _finish_restores(users)


def adopt_group_copies(nodes):
    """Point each of `nodes` (HBAO nodes) that uses another local group, or
    none (pasted from another file), at the shared current one, keeping its
    values and links: File > Append brings its own copy (".HBAO.001"),
    perhaps of an older layout. A copy of the current layout edited since
    the add-on built it (nodes added, removed or rewired: group_layout.edited)
    was made single-user by the artist: it is kept. A copy left without
    users is removed (not one with a fake user, or an asset). Nodes in
    linked or overridden trees are left alone. Returns how many nodes
    moved."""
    nodes = [node for node in nodes if not node_place.from_another_file(node.id_data)]
    upgrade_group_tree()  # an outdated or half rebuilt shared group first
    _finish_restores(nodes)
    strays = [node for node in nodes if node.node_tree is None or (
        node.node_tree.name != GROUP_TREE_NAME and node.node_tree.library is None
        and not (group_layout.is_current(node.node_tree)
                 and group_layout.edited(node.node_tree)))]
    if not strays:
        return 0
    shared = group_tree()
    for node in strays:
        copy = node.node_tree
        _keep_state(node)
        node.node_tree = shared
        _finish_restores([node])
        if copy is not None and copy.users == 0:
            bpy.data.node_groups.remove(copy)
    return len(strays)


def group_tree():
    """The shared group tree, created or rebuilt when missing or outdated."""
    tree = bpy.data.node_groups.get(GROUP_TREE_NAME)
    if group_layout.is_current(tree) and tree.library is None:
        return tree
    if tree is None or tree.library is not None:
        tree = bpy.data.node_groups.new(GROUP_TREE_NAME, "CompositorNodeTree")
        group_layout.build(tree)
    else:
        upgrade_group_tree()
    tree.use_fake_user = False
    return tree
