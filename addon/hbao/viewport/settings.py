# SPDX-License-Identifier: GPL-2.0-or-later
"""Per-3D-view preview settings, saved in the .blend: a collection of them on
each Screen (a 3D view is no ID block, its Screen is), one entry per 3D view
that ever had the preview on; view_entries.py says which entry is whose."""
import bpy
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty,
                       IntProperty)

from .. import compat, native, parameters, socket_values
from . import projection, view_entries
from ..node import hbao_nodes
from ..parameters import FALLOFF_ITEMS, INTEGRATION_ITEMS


def _enabled_changed(_self, _context):
    for callback in view_entries.enabled_change_callbacks:
        callback()


def _redraw(_self, context):
    # The preview redraws with the view; a changed setting must redraw it now.
    if context is not None and context.area is not None:
        context.area.tag_redraw()


_D = parameters.DEFAULTS
_TIPS = parameters.DESCRIPTIONS


class HBAOViewSettings(bpy.types.PropertyGroup):
    """The preview settings of one 3D view (see the module's docstring)."""
    area_index: IntProperty(
        name="Area Index", default=-1,
        description="Position of this view's area in its screen, refreshed on save")
    enabled: BoolProperty(
        name="HBAO Preview", default=False, update=_enabled_changed,
        description="Multiply ambient occlusion over this 3D view (Solid and Material "
                    "Preview shading)")
    use_node_settings: BoolProperty(
        name="Use Node Settings", default=False, update=_redraw,
        description="Preview with the settings of the scene's HBAO compositor node (its "
                    "values at the current frame), so the view shows what the render will")
    radius: FloatProperty(
        name="Radius", default=_D["radius"], min=0.0, soft_max=10.0, unit="LENGTH",
        update=_redraw, description=_TIPS["radius"])
    angle_bias_degrees: FloatProperty(
        name="Angle Bias", default=_D["angle_bias_degrees"], min=0.0,
        max=parameters.MAX_ANGLE_BIAS_DEGREES, update=_redraw,
        description=_TIPS["angle_bias_degrees"])
    directions: IntProperty(
        name="Directions", default=_D["directions"], min=1, max=parameters.MAX_DIRECTIONS,
        update=_redraw, description=_TIPS["directions"])
    steps: IntProperty(
        name="Steps", default=_D["steps"], min=1, max=parameters.MAX_STEPS,
        update=_redraw, description=_TIPS["steps"])
    falloff: EnumProperty(name="Falloff", items=FALLOFF_ITEMS, default=_D["falloff"],
                          update=_redraw)
    integration: EnumProperty(name="Integration", items=INTEGRATION_ITEMS,
                              default=_D["integration"], update=_redraw)
    blur_size: IntProperty(
        name="Blur Size", default=_D["blur_size"], min=0, max=parameters.MAX_BLUR_SIZE,
        update=_redraw, description=_TIPS["blur_size"])
    blur_sharpness: FloatProperty(
        name="Blur Sharpness", default=_D["blur_sharpness"], min=0.0,
        max=parameters.MAX_BLUR_SHARPNESS, soft_max=64.0, update=_redraw,
        description=_TIPS["blur_sharpness"])
    strength: FloatProperty(
        name="Strength", default=_D["strength"], min=0.0, max=parameters.MAX_STRENGTH,
        soft_max=4.0, update=_redraw, description=_TIPS["strength"])
    thickness: FloatProperty(
        name="Thickness", default=_D["thickness"], min=0.0, soft_max=2.0, unit="LENGTH",
        update=_redraw, description=_TIPS["thickness"])
    half_resolution: BoolProperty(
        name="Half Resolution", default=False, update=_redraw,
        description=_TIPS["half_resolution"])

    def params(self, scene=None):
        """The C library's parameters (native.compute_ao's dict) this view
        previews with: those of `scene`'s (default: the context's) first HBAO
        node when use_node_settings is on and there is one, else these
        settings. Raises ValueError for a value the library refuses."""
        node = self.settings_node(scene) if self.use_node_settings else None
        if node is not None:
            scene = scene or bpy.context.scene
            params = socket_values.node_params(node, scene, scene.frame_current, [])
        else:
            values = {name: getattr(self, name) for name in parameters.DEFAULTS
                      if name != "background_depth"}
            values["half_resolution"] = int(self.half_resolution)
            params = native.resolve_params(values)
        return dict(params, background_depth=projection.BACKGROUND_DEPTH)

    @staticmethod
    def settings_node(scene=None):
        """The HBAO node "Use Node Settings" previews: the first of the scene's
        compositor tree, or None."""
        scene = scene or bpy.context.scene
        nodes = hbao_nodes(compat.compositor_tree(scene)) if scene is not None else []
        return nodes[0] if nodes else None


CLASSES = (HBAOViewSettings,)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    setattr(bpy.types.Screen, view_entries.COLLECTION_NAME,
            CollectionProperty(type=HBAOViewSettings))
    bpy.app.handlers.save_pre.append(view_entries.refresh_area_indices)
    bpy.app.handlers.load_pre.append(view_entries.forget_areas)


def unregister():
    for handlers, function in (
            (bpy.app.handlers.save_pre, view_entries.refresh_area_indices),
            (bpy.app.handlers.load_pre, view_entries.forget_areas)):
        while function in handlers:
            handlers.remove(function)
    view_entries.forget_areas()
    delattr(bpy.types.Screen, view_entries.COLLECTION_NAME)
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
