# SPDX-License-Identifier: GPL-2.0-or-later
"""Per-3D-view preview settings, saved in the .blend.

Where they live, and why: a 3D view (SpaceView3D) and its area are not ID
blocks, so Python cannot add properties to them. The Screen that holds the
area is an ID (one per workspace and window layout) and is saved with the file,
so each Screen carries a collection `hbao_viewport_views` with one entry per 3D
view that ever had the preview turned on, keyed by the area's position in
`screen.areas`. Areas have no stable identifier across saves, and their
positions shift when an area before them is joined away, so while Blender runs
an entry follows its area by the area's memory address (which stays valid as
long as the area exists), and the saved positions are refreshed just before
every save. Per scene or per workspace settings would be simpler but are not per
view: two 3D views side by side could not differ.
"""
import bpy
from bpy.app.handlers import persistent
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty,
                       IntProperty)

from .. import compat, native, parameters, socket_values
from ..callback_guard import never_raises
from . import projection
from ..node import hbao_nodes
from ..parameters import FALLOFF_ITEMS, INTEGRATION_ITEMS

COLLECTION_NAME = "hbao_viewport_views"
# Blender names a maximized or full-screen area's temporary screen
# "<home screen>-nonnormal".
TEMPORARY_SUFFIX = "-nonnormal"

# (screen pointer, area pointer) -> entry name, for the areas seen this session.
_entry_by_area = {}
# space pointer -> (screen name, entry name): a maximized or full-screen view
# moves its space into a temporary screen, where it keeps its settings.
_entry_by_space = {}
# Called with no arguments when a view's `enabled` changes (draw.sync_handler).
enabled_change_callbacks = []


def _enabled_changed(_self, _context):
    for callback in enabled_change_callbacks:
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


def _views(screen):
    return getattr(screen, COLLECTION_NAME)


def _area_index(screen, area):
    for index, candidate in enumerate(screen.areas):
        if candidate == area:
            return index
    return -1


def find(screen, area):
    """The settings of the 3D view in `area`, or None if it has none yet; a
    maximized view's are its own screen's. Reads only, so panels and draw
    callbacks may call it."""
    if screen is None or area is None:
        return None
    space = area.spaces.active
    entry = _find_on_screen(screen, area)
    if entry is not None:
        if space is not None:
            _entry_by_space[space.as_pointer()] = (screen.name, entry.name)
        return entry
    if space is not None and _temporary(screen):
        home_name, name = _entry_by_space.get(space.as_pointer(), (None, None))
        home = bpy.data.screens.get(home_name) if home_name is not None else None
        if home is not None and home != screen:
            return _views(home).get(name)
    return None


def _temporary(screen):
    """A screen Blender makes for a maximized (Ctrl+Space, show_fullscreen)
    or full-screen (Ctrl+Alt+Space) area: it names both "<screen>-nonnormal"."""
    return getattr(screen, "show_fullscreen", False) or screen.name.endswith(TEMPORARY_SUFFIX)


def _home_place(screen):
    """The home screen of temporary `screen` and the area there that its view
    left (Blender leaves an empty area in its place, and moves the view back
    into it on return), or (None, None) where either is not found: a home
    name too long to be kept whole, or no single empty area."""
    if not screen.name.endswith(TEMPORARY_SUFFIX):
        return None, None
    home = bpy.data.screens.get(screen.name[:-len(TEMPORARY_SUFFIX)])
    if home is None or home == screen:
        return None, None
    empty = [area for area in home.areas if area.type == "EMPTY"]
    return (home, empty[0]) if len(empty) == 1 else (None, None)


def _find_on_screen(screen, area):
    views = _views(screen)
    key = (screen.as_pointer(), area.as_pointer())
    name = _entry_by_area.get(key)
    if name is not None:
        entry = views.get(name)
        if entry is not None:
            return entry
    index = _area_index(screen, area)
    # Entries that follow another live area of this screen are taken; an entry
    # whose area was closed is free again.
    live = {candidate.as_pointer() for candidate in screen.areas}
    claimed = {n for (s, a), n in _entry_by_area.items() if s == key[0] and a in live}
    for entry in views:
        if entry.area_index == index and entry.name not in claimed:
            _entry_by_area[key] = entry.name
            return entry
    return None


def ensure(screen, area):
    """The settings of the 3D view in `area`, created if needed (writes the
    Screen: call from operators, not from draw code). A maximized view's
    are made on its home screen (_home_place), so that they are still
    there when the view comes back."""
    entry = find(screen, area)
    if entry is not None:
        return entry
    home, place = _home_place(screen) if _temporary(screen) else (None, None)
    space = area.spaces.active
    if home is not None and space is not None:
        entry = ensure(home, place)
        _entry_by_space[space.as_pointer()] = (home.name, entry.name)
        return entry
    views = _views(screen)
    existing = {entry.name for entry in views}
    number = len(views) + 1
    while f"View {number}" in existing:
        number += 1
    entry = views.add()
    entry.name = f"View {number}"
    entry.area_index = _area_index(screen, area)
    _entry_by_area[(screen.as_pointer(), area.as_pointer())] = entry.name
    return entry


def any_enabled():
    """Whether any 3D view of any screen has the preview on."""
    return any(entry.enabled for screen in bpy.data.screens for entry in _views(screen))


@persistent
@never_raises("note the viewport preview's views before the save")
def _refresh_area_indices(*_args):
    """Before a save: write each entry's current area position, so the file maps
    entries to the right areas when it is opened again."""
    for screen in bpy.data.screens:
        views = _views(screen)
        screen_pointer = screen.as_pointer()
        for index, area in enumerate(screen.areas):
            name = _entry_by_area.get((screen_pointer, area.as_pointer()))
            entry = views.get(name) if name is not None else None
            if entry is not None and entry.area_index != index:
                entry.area_index = index


@persistent
@never_raises("forget the viewport preview's views of the file closed")
def _forget_areas(*_args):
    """After a load: areas are new objects; entries are found by position again."""
    _entry_by_area.clear()
    _entry_by_space.clear()


CLASSES = (HBAOViewSettings,)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    setattr(bpy.types.Screen, COLLECTION_NAME, CollectionProperty(type=HBAOViewSettings))
    bpy.app.handlers.save_pre.append(_refresh_area_indices)
    bpy.app.handlers.load_pre.append(_forget_areas)


def unregister():
    for handlers, function in ((bpy.app.handlers.save_pre, _refresh_area_indices),
                               (bpy.app.handlers.load_pre, _forget_areas)):
        while function in handlers:
            handlers.remove(function)
    _entry_by_area.clear()
    _entry_by_space.clear()
    delattr(bpy.types.Screen, COLLECTION_NAME)
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
