# SPDX-License-Identifier: GPL-2.0-or-later
"""The sidebar panel (N panel, tab "HBAO") and the operator that turns the
preview on and off for one 3D view."""
import bpy

from . import draw, settings


class HBAO_OT_viewport_preview_toggle(bpy.types.Operator):
    """Turn the HBAO preview of this 3D view on or off"""
    bl_idname = "hbao.viewport_preview_toggle"
    bl_label = "HBAO Preview"
    bl_options = {"REGISTER"}

    @classmethod
    def poll(cls, context):
        return context.area is not None and context.area.type == "VIEW_3D"

    def execute(self, context):
        view_settings = settings.ensure(context.screen, context.area)
        view_settings.enabled = not view_settings.enabled  # the update syncs the handler
        return {"FINISHED"}


class VIEW3D_PT_hbao_preview(bpy.types.Panel):
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "HBAO"
    bl_label = "HBAO Preview"

    def draw_header(self, context):
        view_settings = settings.find(context.screen, context.area)
        if view_settings is not None:
            self.layout.prop(view_settings, "enabled", text="")

    def draw(self, context):
        layout = self.layout
        view_settings = settings.find(context.screen, context.area)
        if view_settings is None:
            # Panels may not write the Screen; the operator creates the settings.
            layout.operator(HBAO_OT_viewport_preview_toggle.bl_idname,
                            text="Turn On", icon="SHADING_SOLID")
            return
        if context.space_data.shading.type not in draw.SHADINGS:
            layout.label(text="Shows in Solid and Material Preview", icon="INFO")
        layout.use_property_split = True
        layout.use_property_decorate = False
        layout.prop(view_settings, "use_node_settings")
        node = view_settings.settings_node(context.scene) \
            if view_settings.use_node_settings else None
        if view_settings.use_node_settings:
            layout.label(text=f"Node \"{node.name}\"" if node else "No HBAO node: using these",
                         icon="NODE" if node else "INFO")
        column = layout.column()
        column.active = view_settings.enabled and node is None
        column.prop(view_settings, "radius")
        column.prop(view_settings, "strength")
        column.prop(view_settings, "angle_bias_degrees")
        column.prop(view_settings, "thickness")
        column.separator()
        column.prop(view_settings, "directions")
        column.prop(view_settings, "steps")
        column.prop(view_settings, "falloff")
        column.prop(view_settings, "integration")
        column.prop(view_settings, "half_resolution")
        column.separator()
        column.prop(view_settings, "blur_size")
        row = column.row()
        row.active = view_settings.blur_size >= 2
        row.prop(view_settings, "blur_sharpness")


CLASSES = (HBAO_OT_viewport_preview_toggle, VIEW3D_PT_hbao_preview)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)


def unregister():
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
