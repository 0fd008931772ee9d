# SPDX-License-Identifier: GPL-2.0-or-later
"""The sidebar panel (N panel, tab "HBAO") and the operator that turns the
preview on and off for one 3D view."""
import bpy

from .. import native, parameters, ui_text
from . import draw, view_entries


class HBAO_OT_viewport_preview_toggle(bpy.types.Operator):
    """Turn the HBAO preview of this 3D view on or off"""
    bl_idname = "hbao.viewport_preview_toggle"
    bl_label = "HBAO Preview"
    bl_options = {"REGISTER"}

    @classmethod
    def poll(cls, context):
        return context.area is not None and context.area.type == "VIEW_3D"

    def execute(self, context):
        view_settings = view_entries.ensure(context.screen, context.area)
        view_settings.enabled = not view_settings.enabled  # the update syncs the handler
        return {"FINISHED"}


def _wrapped_label(layout, context, text, icon):
    """`text` as lines that fit the sidebar's width, the first with `icon`."""
    characters = ui_text.characters_for(context.region.width,
                                        context.preferences.system.ui_scale)
    ui_text.labels(layout, text, characters, icon)


def software_note(area, view_settings, scene):
    """What the panel says of the preview in the 3D view in `area` where
    Blender draws without a GPU (draw.software_renderer): the last frame's
    time, and what makes it faster; None where it says nothing of it (a GPU,
    the preview off, or not drawn there: the panel says why)."""
    if not view_settings.enabled or not draw.software_renderer():
        return None
    if draw.not_drawn(area.spaces.active) is not None or draw.view_error(area):
        return None
    text = "No GPU: Blender draws with software OpenGL, so the preview runs on the CPU"
    milliseconds = draw.frame_ms(area)
    if milliseconds is not None:
        text += f" ({milliseconds:.0f} ms a frame)"
    if not _half_resolution(view_settings, scene):
        text += ". Half Resolution takes about a third of the time"
    return text + "."


def _half_resolution(view_settings, scene):
    params, _error = _params(view_settings, scene)
    return bool(params and params.get("half_resolution"))


def _params(view_settings, scene):
    """(the parameters the view previews with, None), or (None, why there
    are none: the library missing, a value it refuses)."""
    try:
        return view_settings.params(scene), None
    except Exception as error:
        return None, str(error)


def _length(context, value):
    """A length in scene units as Blender's fields show it (the unit
    system's scale applies only where there is a unit system)."""
    unit = context.scene.unit_settings
    if unit.system == "NONE":
        return f"{value:g}"
    return bpy.utils.units.to_string(unit.system, "LENGTH", value * unit.scale_length)


def _radius_note(layout, radius):
    """At Radius 0 the preview draws no AO: the library's note for it (the
    node says it after a render), which the panel says at once."""
    if radius <= 0.0:
        layout.label(text=native.NOTE_SHORT_FORMS[native.NOTE_RADIUS_UNDER_A_PIXEL],
                     icon="INFO")


def _node_summary(layout, context, view_settings, node, shown_error):
    """What the preview takes from `node` (its values at the current frame),
    read-only: they are edited on the node. `shown_error`: the preview's
    error, which the panel has shown above."""
    _wrapped_label(layout, context, f"Node \"{node.name}\"'s values (edit them there):",
                   "NODE")
    params, error = _params(view_settings, context.scene)
    if params is None:
        if not (shown_error and error in shown_error):  # (said once: a review's find)
            _wrapped_label(layout, context, error, "ERROR")
        return
    lines = [f"Radius {_length(context, params['radius'])}",
             f"Strength {params['strength']:g}",
             f"{params['directions']} directions x {params['steps']} steps",
             f"Angle bias {params['angle_bias_degrees']:g} degrees",
             f"Thickness {_length(context, params['thickness'])}"
             if params["thickness"] > 0.0 else "Thickness: no limit",
             f"Blur size {params['blur_size']}, sharpness {params['blur_sharpness']:g}",
             f"{parameters.item_name(parameters.INTEGRATION_ITEMS, params['integration'])}, "
             f"falloff {parameters.item_name(parameters.FALLOFF_ITEMS, params['falloff'])}"]
    if params.get("half_resolution"):
        lines.append("Half resolution")
    for line in lines:
        layout.label(text=line)
    _radius_note(layout, params["radius"])


class VIEW3D_PT_hbao_preview(bpy.types.Panel):
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "HBAO"
    bl_label = "HBAO Preview"

    def draw_header(self, context):
        view_settings = view_entries.find(context.screen, context.area)
        if view_settings is not None:
            self.layout.prop(view_settings, "enabled", text="")

    def draw(self, context):
        layout = self.layout
        view_settings = view_entries.find(context.screen, context.area)
        if view_settings is None:
            # Panels may not write the Screen; the operator creates the settings.
            layout.operator(HBAO_OT_viewport_preview_toggle.bl_idname,
                            text="Turn On", icon="SHADING_SOLID")
            return
        why_not = draw.not_drawn(context.space_data)
        if why_not is not None:
            _wrapped_label(layout, context, why_not, "INFO")
        error = draw.view_error(context.area) if view_settings.enabled else None
        if error:
            _wrapped_label(layout.box(), context, f"No preview: {error}", "ERROR")
        note = software_note(context.area, view_settings, context.scene)
        if note is not None:
            _wrapped_label(layout, context, note, "INFO")
        # check boxes with their label beside them: the split layout cut
        # "Use Node Settings" and "Half Resolution" short in the sidebar
        layout.prop(view_settings, "use_node_settings")
        layout.use_property_split = True
        layout.use_property_decorate = False
        node = view_settings.settings_node(context.scene) \
            if view_settings.use_node_settings else None
        if view_settings.use_node_settings and node is None:
            layout.label(text="No HBAO node: using these", icon="INFO")
        if node is not None:
            _node_summary(layout.box(), context, view_settings, node, error)
            return
        column = layout.column()
        column.active = view_settings.enabled
        column.prop(view_settings, "radius")
        _radius_note(column, view_settings.radius)
        column.prop(view_settings, "strength")
        column.prop(view_settings, "angle_bias_degrees")
        column.prop(view_settings, "thickness")
        column.separator()
        column.prop(view_settings, "directions")
        column.prop(view_settings, "steps")
        column.prop(view_settings, "falloff")
        column.prop(view_settings, "integration")
        column.separator()
        column.prop(view_settings, "blur_size")
        row = column.row()
        row.active = parameters.blur_kernel_radius(view_settings.blur_size) > 0
        row.prop(view_settings, "blur_sharpness", text="Sharpness")
        column.separator()
        flags = column.column()
        flags.use_property_split = False
        flags.prop(view_settings, "half_resolution")


CLASSES = (HBAO_OT_viewport_preview_toggle, VIEW3D_PT_hbao_preview)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)


def unregister():
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
