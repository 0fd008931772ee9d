# SPDX-License-Identifier: GPL-2.0-or-later
"""The layout of the group tree every HBAO node shares: its name, sockets
(which carry the artist's values) and contents (AO = 1 - the occlusion pass,
Image x AO), and the version that says which layout a file's group has.
node_group.py keeps the nodes' values and links while a group changes."""
from . import compat, compat_nodes, parameters, pass_encoding

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


def build(tree):
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
    tree[BUILT_KEY] = fingerprint(tree)


def layout_of(node):
    """The layout (GROUP_TREE_VERSION) of an HBAO node's group."""
    tree = node.node_tree
    return tree.get(GROUP_VERSION_KEY, 1) if tree is not None else GROUP_TREE_VERSION


def no_ao_value(node):
    """The pass input value that means no AO to `node`'s group."""
    return pass_encoding.no_ao_for_layout(layout_of(node))


def is_current(tree):
    return tree is not None and tree.get(GROUP_VERSION_KEY) == GROUP_TREE_VERSION


# What build() made, kept in the group (copies carry it): a group whose
# fingerprint differs from its own kept one was edited (node_group.py).
BUILT_KEY = "hbao_group_built"


def fingerprint(tree):
    """The group's nodes (by name), its number of links and its sockets:
    what an edit that adds, removes or rewires nodes changes, and what
    Blender's versioning of an older file (a Mix node replaced by another
    of the same name, a setting added) does not."""
    sockets = [compat.group_socket_names(tree, in_out) for in_out in ("INPUT", "OUTPUT")]
    return repr((sorted(node.name for node in tree.nodes), len(tree.links), sockets))


def edited(tree):
    """Whether group `tree`, made by build(), was edited since (not a group
    made before build() kept its fingerprint)."""
    built = tree.get(BUILT_KEY)
    return built is not None and built != fingerprint(tree)
