# SPDX-License-Identifier: GPL-2.0-or-later
"""The HBAO compositor node (Add > Filter > HBAO).

It is a custom group node: its group multiplies Image by the AO pass that the
render hook (helper_scene.py, engine.py) computes with this node's settings
and publishes through a Render Layers node. The group's inputs other than
Image only carry the artist's values; the hook reads them. The node knows
nothing of the hook: it announces that nodes came or went through
`changed_callbacks`, which the hook subscribes to."""
import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty

from . import compat, parameters
from .parameters import FALLOFF_ITEMS, INTEGRATION_ITEMS

NODE_IDNAME = "CompositorNodeHBAO"
# One group tree shared by every HBAO node (the values live on each node's
# own sockets). The leading dot hides it from data-block menus.
GROUP_TREE_NAME = ".HBAO"
# Bumped when the group's sockets or contents change; older trees are rebuilt.
GROUP_TREE_VERSION = 1
GROUP_VERSION_KEY = "hbao_group_version"

IMAGE_INPUT = "Image"
DEPTH_INPUT = "Depth"
NORMAL_INPUT = "Normal"
# The hidden input the hook links the computed AO pass to. Its default, 1,
# is what the node outputs when the hook could not run: no AO, no harm.
AO_PASS_INPUT = "HBAO Pass"
IMAGE_OUTPUT = "Image"
AO_OUTPUT = "AO"

# The radius socket's upper end: far beyond any scene, but finite.
MAX_RADIUS = 1.0e4

# The parameters an artist can animate or drive with a Value node: one float
# socket each, named as parameters.LABELS names it -> (params key, default,
# socket min, socket max), the range the library's limits (parameters.LIMITS).
_D = parameters.DEFAULTS
VALUE_INPUTS = {
    parameters.LABELS[key]: (key, float(_D[key]),
                             *((0.0, MAX_RADIUS) if key == "radius"
                               else (float(parameters.LIMITS[key][0]),
                                     float(parameters.LIMITS[key][1]))))
    for key in ("radius", "angle_bias_degrees", "directions", "steps", "blur_size", "strength")
}
# Called with no arguments when an HBAO node is added, copied or deleted
# (the hook's handlers subscribe: node callbacks must not edit the tree).
changed_callbacks = []


def _new_input(tree, socket_type, name, default=None, minimum=None, maximum=None):
    socket = compat.new_group_socket(tree, "INPUT", socket_type, name)
    if default is not None:
        socket.default_value = default
    if minimum is not None:
        socket.min_value = minimum
        socket.max_value = maximum
    return socket


def _build_group_tree(tree):
    tree.nodes.clear()
    compat.clear_group_interface(tree)
    _new_input(tree, "NodeSocketColor", IMAGE_INPUT, (1.0, 1.0, 1.0, 1.0))
    _new_input(tree, "NodeSocketFloat", DEPTH_INPUT, 0.0)
    _new_input(tree, "NodeSocketVector", NORMAL_INPUT)
    for name, (_key, default, minimum, maximum) in VALUE_INPUTS.items():
        _new_input(tree, "NodeSocketFloat", name, default, minimum, maximum)
    _new_input(tree, "NodeSocketFloat", AO_PASS_INPUT, 1.0, 0.0, 1.0)
    compat.new_group_socket(tree, "OUTPUT", "NodeSocketColor", IMAGE_OUTPUT)
    compat.new_group_socket(tree, "OUTPUT", "NodeSocketFloat", AO_OUTPUT)

    group_input = tree.nodes.new("NodeGroupInput")
    group_input.location = (-300, 0)
    group_output = tree.nodes.new("NodeGroupOutput")
    group_output.location = (300, 0)
    multiply, colour_a, colour_b, product = compat.new_multiply_node(tree)
    multiply.name = multiply.label = "Image x AO"
    tree.links.new(group_input.outputs[IMAGE_INPUT], colour_a)
    tree.links.new(group_input.outputs[AO_PASS_INPUT], colour_b)
    tree.links.new(product, group_output.inputs[IMAGE_OUTPUT])
    tree.links.new(group_input.outputs[AO_PASS_INPUT], group_output.inputs[AO_OUTPUT])
    tree[GROUP_VERSION_KEY] = GROUP_TREE_VERSION


def group_tree():
    """The shared group tree, created or rebuilt when missing or outdated."""
    tree = bpy.data.node_groups.get(GROUP_TREE_NAME)
    up_to_date = tree is not None and tree.get(GROUP_VERSION_KEY) == GROUP_TREE_VERSION
    if up_to_date and tree.library is None:
        return tree
    if tree is None or tree.library is not None:
        tree = bpy.data.node_groups.new(GROUP_TREE_NAME, "CompositorNodeTree")
    _build_group_tree(tree)
    tree.use_fake_user = False
    return tree


def is_hbao_node(node):
    return getattr(node, "bl_idname", "") == NODE_IDNAME


def hbao_nodes(tree):
    """The HBAO nodes at the top level of a compositor tree."""
    return [node for node in tree.nodes if is_hbao_node(node)] if tree else []


def pass_name(node):
    """Name of the Render Layers output that carries this node's AO."""
    return f"HBAO {node.pass_index}"


def next_pass_index(tree, exclude=None):
    used = {node.pass_index for node in hbao_nodes(tree) if node != exclude}
    index = 1
    while index in used:
        index += 1
    return index


def _announce_change():
    for callback in changed_callbacks:
        callback()


def _settings_changed(node, _context):
    # Nothing to rebuild: the hook reads the node at render time. Re-running
    # the compositor shows the new result in the backdrop.
    node.id_data.update_tag()


class CompositorNodeHBAO(bpy.types.CompositorNodeCustomGroup):
    """Horizon-based ambient occlusion from the Depth (and Normal) pass"""
    bl_idname = NODE_IDNAME
    bl_label = "HBAO"
    bl_icon = "SHADING_RENDERED"
    bl_width_default = 180

    falloff: EnumProperty(name="Falloff", items=FALLOFF_ITEMS, default=_D["falloff"],
                          update=_settings_changed)
    integration: EnumProperty(name="Integration", items=INTEGRATION_ITEMS,
                              default=_D["integration"], update=_settings_changed)
    half_resolution: BoolProperty(
        name="Half Resolution", default=False, update=_settings_changed,
        description="Compute AO at half resolution and upsample it, depth-aware (faster)")
    blur_sharpness: FloatProperty(
        name="Blur Sharpness", default=_D["blur_sharpness"], min=0.0,
        max=parameters.MAX_BLUR_SHARPNESS, soft_max=64.0,
        update=_settings_changed,
        description="How strongly the blur stops at depth edges; 0 = plain Gaussian")
    pass_index: IntProperty(name="Pass Index", default=0, min=0,
                            description="Number of the AO pass the render hook fills for "
                                        "this node")
    status: StringProperty(name="Status", default="",
                           description="Last message from the render hook about this node")

    @classmethod
    def poll(cls, tree):
        return tree.bl_idname == "CompositorNodeTree"

    def init(self, context):
        self.node_tree = group_tree()
        self.pass_index = next_pass_index(self.id_data, exclude=self)
        self.width = self.bl_width_default
        _announce_change()

    def copy(self, node):
        self.node_tree = node.node_tree
        self.pass_index = next_pass_index(self.id_data, exclude=self)
        _announce_change()

    def free(self):
        # The shared group tree stays; the hook drops this node's pass and,
        # with the last HBAO node, its own Render Layers node, on its next sync.
        _announce_change()

    def draw_buttons(self, context, layout):
        layout.prop(self, "falloff")
        layout.prop(self, "integration")
        layout.prop(self, "half_resolution")
        if self.status:
            layout.label(text=self.status, icon="INFO")

    def draw_buttons_ext(self, context, layout):
        self.draw_buttons(context, layout)
        layout.prop(self, "blur_sharpness")
        layout.label(text=f"AO pass: {pass_name(self)}")

    def draw_label(self):
        return "HBAO"


def _draw_add_menu(menu, context):
    space = context.space_data
    if getattr(space, "tree_type", "") != "CompositorNodeTree":
        return
    operator = menu.layout.operator("node.add_node", text="HBAO")
    operator.type = NODE_IDNAME
    operator.use_transform = True


def register():
    bpy.utils.register_class(CompositorNodeHBAO)
    menu = compat.compositor_filter_menu()
    if menu is not None:
        menu.append(_draw_add_menu)


def unregister():
    menu = compat.compositor_filter_menu()
    if menu is not None:
        menu.remove(_draw_add_menu)
    bpy.utils.unregister_class(CompositorNodeHBAO)
