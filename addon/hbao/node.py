# SPDX-License-Identifier: GPL-2.0-or-later
"""The HBAO compositor node (Add > Filter > HBAO).

It is a custom group node: its group multiplies Image by the AO pass that the
render hook (helper_scene.py, helper_ao.py) computes with this node's settings
and publishes through a Render Layers node. The group's inputs other than
Image only carry the artist's values; the hook reads them. The node knows
nothing of the hook: it announces that nodes came or went through
`changed_callbacks`, which the hook subscribes to."""
import atexit

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty

from . import compat, guard_geometry, node_lines, node_place, parameters, writes
from .callback_guard import never_raises
from .compositor_effects import NODE_IDNAME, is_hbao_node
from .group_layout import (AO_OUTPUT, AO_PASS_INPUT, DEPTH_INPUT, GROUP_TREE_NAME,  # noqa: F401
                           IMAGE_INPUT, IMAGE_OUTPUT, NORMAL_INPUT, VALUE_INPUTS)
from .node_group import adopt_group_copies, group_tree, keep_copied_values, upgrade_group_tree
from .parameters import FALLOFF_ITEMS, INTEGRATION_ITEMS

_D = parameters.DEFAULTS
# Called with no arguments when an HBAO node is added, copied or deleted
# (the hook's handlers subscribe: node callbacks must not edit the tree).
changed_callbacks = []


def hbao_nodes(tree):
    """The HBAO nodes at the top level of a compositor tree."""
    return [node for node in tree.nodes if is_hbao_node(node)] if tree else []


def adopt_group_copies_of(scenes):
    """node_group.adopt_group_copies for the HBAO nodes of `scenes`'
    compositor trees (5.x scenes may share one) and of the compositor node
    groups (an artist's group that holds one: appended with it)."""
    trees = {tree.as_pointer(): tree for tree in map(compat.compositor_tree, scenes) if tree}
    trees.update((group.as_pointer(), group) for group in bpy.data.node_groups
                 if group.bl_idname == "CompositorNodeTree"
                 and not group.name.startswith(GROUP_TREE_NAME))
    return adopt_group_copies([node for tree in trees.values() for node in hbao_nodes(tree)])


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
    # Nothing to rebuild: the hook reads the node when Blender renders; the
    # AO of an existing render is not computed again (README, Limits), and
    # the node says so (node_status.hint_refreshers).
    node.id_data.update_tag()


def _extra_render_changed(node, _context):
    # The hook makes or removes the extra render on its next sync.
    node.id_data.update_tag()
    _announce_change()


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
        description=parameters.DESCRIPTIONS["half_resolution"])
    guard_band: FloatProperty(
        name="Guard Band", default=0.0, min=0.0, max=100.0 * guard_geometry.MAX_GUARD_BAND,
        subtype="PERCENTAGE", update=_extra_render_changed, options=set(),
        description="Lets image borders see what lies past the frame, by also looking this "
                    "far past each side (% of the frame); without it, the surfaces at the "
                    "frame's edge are taken as going on flat. Costs a quick extra render "
                    "(Cycles, 1 sample, Depth and Normal only). 0 = off")
    back_faces: BoolProperty(
        name="Back Faces", default=False, update=_extra_render_changed, options=set(),
        description="Lets light pass between an object and the surface behind it, which "
                    "removes the dark halo around foreground objects; costs a quick extra "
                    "render of the back faces (Cycles, 1 sample, Depth only)")
    blur_sharpness: FloatProperty(
        name="Blur Sharpness", default=_D["blur_sharpness"], min=0.0,
        max=parameters.MAX_BLUR_SHARPNESS, soft_max=64.0,
        update=_settings_changed,
        description=parameters.DESCRIPTIONS["blur_sharpness"])
    pass_index: IntProperty(name="Pass Index", default=0, min=0,
                            description="Number of the AO pass the render hook fills for "
                                        "this node")
    status: StringProperty(name="Status", default="",
                           description="Last message from the render hook about this node")
    status_details: StringProperty(name="Status Details", default="",
                                   description="The full text of the render hook's messages")
    status_record: StringProperty(name="Status Record", default="",
                                  description="The status line's messages and what each is "
                                              "about, for the add-on to check once the file "
                                              "is opened again")
    hint: StringProperty(name="Hint", default="",
                         description="Whether the AO shown is still the last render's")
    hint_details: StringProperty(name="Hint Details", default="")

    @classmethod
    def poll(cls, tree):
        return tree.bl_idname == "CompositorNodeTree"

    def init(self, context):
        self.node_tree = group_tree()
        self.pass_index = next_pass_index(self.id_data, exclude=self)
        self.width = self.bl_width_default
        _announce_change()

    def copy(self, node):
        # Blender copies the group with the node. `node.node_tree` is not
        # read: pasted into another file, `node` is the clipboard's, whose
        # group may be a closed file's (3.4 crashed, an exploratory run).
        keep_copied_values(self, node)
        self.pass_index = next_pass_index(self.id_data, exclude=self)
        _announce_change()

    def free(self):
        # The shared group tree stays; the hook drops this node's pass and,
        # with the last HBAO node, its own Render Layers node, on its next sync.
        _announce_change()

    def draw_buttons(self, context, layout):
        misplaced = node_place.misplaced(self)
        if misplaced is not None:
            node_lines.draw(layout, *misplaced, "ERROR")
        elif self.node_tree is None or DEPTH_INPUT not in self.inputs:
            # pasted from another file without its group: the add-on's next
            # sync gives it the shared group and its values again
            node_lines.draw(layout, "Setting up...", "Pasted without its node group: the add-on "
                            "gives it the group and its values on its next update", "INFO")
        elif not self.inputs[DEPTH_INPUT].is_linked:
            # Render Layers shows no Depth output until the pass is ticked.
            # (the add-on disabled, its node type kept: no operator to offer)
            if getattr(bpy.types, "HBAO_OT_connect_passes", None) is not None:
                button = layout.operator("hbao.connect_passes", icon="LINKED")
                button.node_name = self.name
        for name in ("falloff", "integration"):
            # A label of its own: the default split cuts "Integration" short.
            row = layout.split(factor=0.5)
            row.label(text=self.bl_rna.properties[name].name)
            row.prop(self, name, text="")
        layout.prop(self, "half_resolution")
        layout.prop(self, "guard_band")
        layout.prop(self, "back_faces")
        node_lines.draw(layout, *writes.stuck_line(), "ERROR")
        node_lines.draw(layout, self.status, self.status_details, "ERROR")
        node_lines.draw(layout, self.hint, self.hint_details, "INFO")

    def draw_buttons_ext(self, context, layout):
        self.draw_buttons(context, layout)
        layout.prop(self, "blur_sharpness")
        # where the render hook delivers this node's AO (into its hidden input)
        layout.label(text=f"AO arrives as pass \"{pass_name(self)}\"")

    def draw_label(self):
        return "HBAO"


@bpy.app.handlers.persistent
@never_raises("update the HBAO node group of the file opened")
def _on_load_post(*_args):
    upgrade_group_tree()


_HANDLERS = (("load_post", _on_load_post),)


def _draw_add_menu(menu, context):
    space = context.space_data
    if getattr(space, "tree_type", "") != "CompositorNodeTree":
        return
    operator = menu.layout.operator("node.add_node", text="HBAO")
    operator.type = NODE_IDNAME
    operator.use_transform = True


@never_raises("let go of the HBAO node type as Python exits")
def _release_node_type_at_exit():
    """compat.NODE_TYPE_HOLDS_MODULE_AT_EXIT: the type, registered or kept,
    goes as the script's Python exits (atexit: before bpy's own exit)."""
    if "bl_rna" in CompositorNodeHBAO.__dict__:
        bpy.utils.unregister_class(CompositorNodeHBAO)


def register():
    if "bl_rna" not in CompositorNodeHBAO.__dict__:  # kept (compat.keep_node_type_registered)
        bpy.utils.register_class(CompositorNodeHBAO)
    if compat.NODE_TYPE_HOLDS_MODULE_AT_EXIT:
        atexit.unregister(_release_node_type_at_exit)  # (once, enabled again or not)
        atexit.register(_release_node_type_at_exit)
    bpy.utils.register_class(node_lines.HBAO_OT_node_status)
    for name, function in _HANDLERS:
        getattr(bpy.app.handlers, name).append(function)
    menu = compat.compositor_filter_menu()
    if menu is not None:
        menu.append(_draw_add_menu)


def unregister():
    menu = compat.compositor_filter_menu()
    if menu is not None:
        menu.remove(_draw_add_menu)
    for name, function in _HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        while function in handlers:
            handlers.remove(function)
    bpy.utils.unregister_class(node_lines.HBAO_OT_node_status)
    if ("bl_rna" in CompositorNodeHBAO.__dict__  # (gone at exit: _release_node_type_at_exit)
            and not compat.keep_node_type_registered(NODE_IDNAME)):
        bpy.utils.unregister_class(CompositorNodeHBAO)
