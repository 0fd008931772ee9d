# SPDX-License-Identifier: GPL-2.0-or-later
"""Compositor nodes as each Blender makes them: 5.0 renamed or reshaped
several (the shared Mix, Math and Value nodes, the Group Output for the
Composite node, renamed passes). The add-on uses the Mix and Math nodes
and the passes; our scripts and tests the Value and output nodes too."""
from .compat import HAS_COMPOSITING_NODE_GROUP, group_socket_names, new_group_socket


def new_multiply_node(tree):
    """A node that multiplies a colour by a factor-like value (Image x AO).
    Returns (node, first colour input, second input, output)."""
    try:
        node = tree.nodes.new("CompositorNodeMixRGB")
        node.blend_type = "MULTIPLY"
        node.inputs[0].default_value = 1.0
        return node, node.inputs[1], node.inputs[2], node.outputs[0]
    except RuntimeError:
        # 5.x compositor: the shared Mix node in RGBA mode.
        node = tree.nodes.new("ShaderNodeMix")
        node.data_type = "RGBA"
        node.blend_type = "MULTIPLY"
        node.inputs["Factor"].default_value = 1.0
        colour_inputs = [s for s in node.inputs if s.type == "RGBA"]
        colour_output = [s for s in node.outputs if s.type == "RGBA"][0]
        return node, colour_inputs[0], colour_inputs[1], colour_output


def new_one_minus_node(tree):
    """A Math node that outputs 1 - x (one float subtraction, exact where
    x lies in [0, 0.5]). Returns (node, the x input, output)."""
    try:
        node = tree.nodes.new("CompositorNodeMath")
    except RuntimeError:  # 5.x compositor: the shared Math node
        node = tree.nodes.new("ShaderNodeMath")
    node.operation = "SUBTRACT"
    node.use_clamp = False
    node.inputs[0].default_value = 1.0
    return node, node.inputs[1], node.outputs[0]


def new_composite_output(tree):
    """The node that receives the final image: Composite (<5.0) or Group Output."""
    if HAS_COMPOSITING_NODE_GROUP:
        node = tree.nodes.new("NodeGroupOutput")
        if "Image" not in group_socket_names(tree, "OUTPUT"):
            new_group_socket(tree, "OUTPUT", "NodeSocketColor", "Image")
        return node
    return tree.nodes.new("CompositorNodeComposite")


def new_value_node(tree):
    """A Value node: CompositorNodeValue before 5.0, ShaderNodeValue since."""
    return tree.nodes.new("ShaderNodeValue" if HAS_COMPOSITING_NODE_GROUP
                          else "CompositorNodeValue")


# Render Layers outputs 5.0 renamed: old name -> new name.
_RENAMED_PASS_OUTPUTS = {"AO": "Ambient Occlusion"}


def pass_output(render_layers, name):
    """A Render Layers node's output by its pre-5.0 name (AO is
    "Ambient Occlusion" since 5.0)."""
    output = render_layers.outputs.get(name)
    if output is None and name in _RENAMED_PASS_OUTPUTS:
        output = render_layers.outputs.get(_RENAMED_PASS_OUTPUTS[name])
    if output is None:
        raise KeyError(f"{render_layers.name} has no {name} output")
    return output
