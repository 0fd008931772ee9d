# SPDX-License-Identifier: GPL-2.0-or-later
"""The group tree every HBAO node shares: its sockets (which carry the
artist's values), its contents (AO = 1 - the occlusion pass, Image x AO), and
its upgrade when a file saved with an older layout is opened."""
import json

import bpy

from . import compat, compat_nodes, parameters, pass_encoding, socket_keys

# One group tree shared by every HBAO node (the values live on each node's
# sockets); the leading dot hides it from data-block menus.
GROUP_TREE_NAME = ".HBAO"
# Bumped when the group's sockets or contents change; older trees are rebuilt
# and the nodes using them keep their values and links (upgrade_group_tree).
# 2: Directions, Steps and Blur Size became integer sockets.
# 3: a Thickness socket after Strength.
# 4: tooltips on every input, Radius and Thickness in scene units, no value
#    fields on Depth, Normal and the hidden AO pass input.
# 5: the hidden pass input carries the occlusion, 1 - AO, default 0: an
#    unwritten pass (the Viewport Compositor's) is no AO, not black
#    (pass_encoding.py, which also says what older groups get).
GROUP_TREE_VERSION = 5
GROUP_VERSION_KEY = "hbao_group_version"

IMAGE_INPUT = "Image"
DEPTH_INPUT = "Depth"
NORMAL_INPUT = "Normal"
# The hidden input the hook links the computed pass to (pass_encoding.py);
# its default, 0, is no AO: the node's output when the hook could not run.
AO_PASS_INPUT = "HBAO Pass"
IMAGE_OUTPUT = "Image"
AO_OUTPUT = "AO"

# The upper end of the radius and thickness sockets (lengths the library
# does not clamp): far beyond any scene, but finite.
MAX_LENGTH = 1.0e4

_D = parameters.DEFAULTS


def _value_input(key):
    """(params key, default, min, max, socket type, subtype) of a value socket:
    the library's limits; whole numbers as integer sockets (4, not 4.000);
    lengths in the scene's unit."""
    if key in ("radius", "thickness"):
        return key, float(_D[key]), 0.0, MAX_LENGTH, "NodeSocketFloat", "DISTANCE"
    low, high, whole = parameters.LIMITS[key]
    if whole:
        return key, int(_D[key]), int(low), int(high), "NodeSocketInt", None
    return key, float(_D[key]), float(low), float(high), "NodeSocketFloat", None


# The parameters an artist can animate or drive with a Value node: one socket
# each, named as parameters.LABELS names it. Their order is part of the file
# format: keyframes address sockets by index (nodes["HBAO"].inputs[3]).
VALUE_INPUTS = {
    parameters.LABELS[key]: _value_input(key)
    for key in ("radius", "angle_bias_degrees", "directions", "steps", "blur_size", "strength",
                "thickness")
}


def _new_input(tree, socket_type, name, default=None, minimum=None, maximum=None,
               subtype=None, description="", hide_value=False):
    socket = compat.new_group_socket(tree, "INPUT", socket_type, name, subtype)
    if default is not None:
        socket.default_value = default
    if minimum is not None:
        socket.min_value = minimum
        socket.max_value = maximum
    socket.description = description
    socket.hide_value = hide_value
    return socket


# The tooltips of the inputs that are not parameters.
IMAGE_TIP = "The render to multiply by the AO (Render Layers' Image)"
DEPTH_TIP = "Render Layers' Depth pass (link it: the AO is computed from it)"
NORMAL_TIP = "Render Layers' Normal pass; unlinked, normals are worked out from the depth"
AO_PASS_TIP = ("Filled by the add-on's helper render with this node's AO: leave it linked "
               "(the node's sidebar names the pass)")


def _build_group_tree(tree):
    tree.nodes.clear()
    compat.clear_group_interface(tree)
    _new_input(tree, "NodeSocketColor", IMAGE_INPUT, (1.0, 1.0, 1.0, 1.0),
               description=IMAGE_TIP)
    _new_input(tree, "NodeSocketFloat", DEPTH_INPUT, 0.0, description=DEPTH_TIP,
               hide_value=True)
    _new_input(tree, "NodeSocketVector", NORMAL_INPUT, description=NORMAL_TIP, hide_value=True)
    for name, (key, default, minimum, maximum, socket_type, subtype) in VALUE_INPUTS.items():
        _new_input(tree, socket_type, name, default, minimum, maximum, subtype,
                   parameters.DESCRIPTIONS[key])
    _new_input(tree, "NodeSocketFloat", AO_PASS_INPUT, pass_encoding.NO_OCCLUSION, 0.0, 1.0,
               description=AO_PASS_TIP, hide_value=True)
    compat.new_group_socket(tree, "OUTPUT", "NodeSocketColor", IMAGE_OUTPUT)
    compat.new_group_socket(tree, "OUTPUT", "NodeSocketFloat", AO_OUTPUT)

    group_input = tree.nodes.new("NodeGroupInput")
    group_output = tree.nodes.new("NodeGroupOutput")
    group_input.location, group_output.location = (-300, 0), (300, 0)
    one_minus, occlusion, ao = compat_nodes.new_one_minus_node(tree)
    one_minus.name = one_minus.label = "AO = 1 - Pass"
    one_minus.location = (-100, -150)
    tree.links.new(group_input.outputs[AO_PASS_INPUT], occlusion)
    multiply, colour_a, colour_b, product = compat_nodes.new_multiply_node(tree)
    multiply.name = multiply.label = "Image x AO"
    multiply.location = (100, 0)
    tree.links.new(group_input.outputs[IMAGE_INPUT], colour_a)
    tree.links.new(ao, colour_b)
    tree.links.new(product, group_output.inputs[IMAGE_OUTPUT])
    tree.links.new(ao, group_output.inputs[AO_OUTPUT])
    tree[GROUP_VERSION_KEY] = GROUP_TREE_VERSION


def layout_of(node):
    """The layout (GROUP_TREE_VERSION) of an HBAO node's group."""
    tree = node.node_tree
    return tree.get(GROUP_VERSION_KEY, 1) if tree is not None else GROUP_TREE_VERSION


def no_ao_value(node):
    """The pass input value that means no AO to `node`'s group."""
    return pass_encoding.no_ao_for_layout(layout_of(node))


def _is_current(tree):
    return tree is not None and tree.get(GROUP_VERSION_KEY) == GROUP_TREE_VERSION


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
                no_ao_value(node) if name == AO_PASS_INPUT
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
        if tree is None or (tree.name == GROUP_TREE_NAME and not _is_current(tree)):
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
    if tree is None or tree.library is not None or _is_current(tree):
        return  # (a restore left pending on a whole group: adopt_group_copies, every sync)
    users = _users(tree)
    for node in users:
        _keep_state(node)
    _build_group_tree(tree)
    _finish_restores(users)


def adopt_group_copies(nodes):
    """Point each of `nodes` (HBAO nodes) that uses another local group, or
    none (pasted from another file), at the shared current one, keeping its
    values and links: File > Append brings its own copy (".HBAO.001"),
    perhaps of an older layout. A copy left without users is removed (not
    one with a fake user, or an asset). Nodes in linked or overridden trees
    are left alone. Returns how many nodes moved."""
    nodes = [node for node in nodes if node.id_data.library is None and
             getattr(node.id_data, "override_library", None) is None]
    upgrade_group_tree()  # an outdated or half rebuilt shared group first
    _finish_restores(nodes)
    strays = [node for node in nodes if node.node_tree is None or (
        node.node_tree.name != GROUP_TREE_NAME and node.node_tree.library is None)]
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
    if _is_current(tree) and tree.library is None:
        return tree
    if tree is None or tree.library is not None:
        tree = bpy.data.node_groups.new(GROUP_TREE_NAME, "CompositorNodeTree")
        _build_group_tree(tree)
    else:
        upgrade_group_tree()
    tree.use_fake_user = False
    return tree
