# SPDX-License-Identifier: GPL-2.0-or-later
"""What the helper scene takes of its main scene's render settings: the
size, so that the helper's result has the main Render Result's, and the
views. The compositor reads each view's AO pass from the helper, and the
helper has a view's pass only where it has the view: with one view, a
stereo render read 0 in both (a black frame); without Multi-View's own
views (besides left and right), those views were black."""
from . import compat, compositor_effects
from .data_edits import set_if_different

SYNCED_RENDER_SETTINGS = (
    "resolution_x", "resolution_y", "resolution_percentage", "pixel_aspect_x",
    "pixel_aspect_y", "use_border", "use_crop_to_border", "border_min_x", "border_max_x",
    "border_min_y", "border_max_y", "fps", "fps_base", "use_multiview", "views_format",
    # Time Remapping: the helper's depsgraph evaluates the main scene's
    # camera at the helper's time, which must be the one rendered.
    "frame_map_old", "frame_map_new")
VIEW_SETTINGS = ("use", "camera_suffix")
# With Render Single Layer on, Blender renders no scene but the one asked
# for, the helper neither: its AO pass goes unwritten (no AO; before the
# group's layout 5, a black image). The hook then unlinks the HBAO nodes from
# it (helper_scene.sync), they pass Image through, and the node says why.
SINGLE_LAYER_DETAIL = ("Render Single Layer is on (View Layer properties): Blender then renders "
                       "no other scene, HBAO's helper neither; AO off (the node passes Image "
                       "through). Turn it off for AO")
SINGLE_LAYER_SHORT = "Single Layer on: AO off"
SINGLE_LAYER_CAUSE = ("single layer",)  # report.NodeMessage's cause (status_causes.py)


# With Compositing off (Output properties, Post Processing), or, before 5.0,
# Use Nodes off in the compositor, Blender runs no compositor: no HBAO node
# either, and the written render has no AO.
COMPOSITING_OFF_DETAIL = ("Compositing is off (Output properties > Post Processing, or the "
                          "compositor's Use Nodes): Blender runs no compositor, so no HBAO node "
                          "runs either, and the render is written without AO. Turn it on for AO")
COMPOSITING_OFF_SHORT = "Compositing off: no AO"
COMPOSITING_OFF_CAUSE = ("compositing off",)


# 5.3: the compositor effect that holds the HBAO nodes switched off for
# renders: Blender runs the others, not it.
EFFECT_OFF_DETAIL = ("The compositor effect \"{effect}\" is off for renders (its Enable for "
                     "Render): Blender runs no HBAO node of it and writes the render without AO. "
                     "Turn it on for AO")
EFFECT_OFF_SHORT = "Effect off for renders: no AO"
EFFECT_OFF_CAUSE = ("effect off",)


def effect_off_detail(scene):
    """EFFECT_OFF_DETAIL for `scene`'s effect where it is off, or None."""
    effect = compositor_effects.off_for_renders(scene)
    return EFFECT_OFF_DETAIL.format(effect=effect.name) if effect is not None else None


# The causes (report.NodeMessage) of the render settings below.
SETTING_CAUSES = (COMPOSITING_OFF_CAUSE, EFFECT_OFF_CAUSE, SINGLE_LAYER_CAUSE)


def _settings_off(scene):
    """(detail, short, cause) of each render setting of `scene` that leaves
    its HBAO nodes without AO now (Compositing off, the effect off for
    renders, Render Single Layer on), the one a render names first."""
    if not compositor_runs(scene):
        yield COMPOSITING_OFF_DETAIL, COMPOSITING_OFF_SHORT, COMPOSITING_OFF_CAUSE
    if (effect_off := effect_off_detail(scene)) is not None:
        yield effect_off, EFFECT_OFF_SHORT, EFFECT_OFF_CAUSE
    if not helper_renders(scene):
        yield SINGLE_LAYER_DETAIL, SINGLE_LAYER_SHORT, SINGLE_LAYER_CAUSE


def ao_off_by(scene):
    """(detail, short, cause) of the render setting that a render of
    `scene` names for its nodes' missing AO, or None."""
    return next(_settings_off(scene), None)


def causes_now(scene):
    """The SETTING_CAUSES that hold for `scene` now (status_causes.py)."""
    return [cause for _detail, _short, cause in _settings_off(scene)]


def compositor_runs(scene):
    """Whether a render of `scene` runs its compositor."""
    return scene.render.use_compositing and (compat.HAS_COMPOSITING_NODE_GROUP
                                             or scene.use_nodes)


def helper_renders(scene):
    """Whether Blender renders the helper with `scene`."""
    return not scene.render.use_single_layer


def keep_compositor_on_cpu(own_scene):
    """4.5 and 5.0 crash (segmentation fault, without the add-on too) rendering
    a scene that a compositor's Render Layers node renders where that scene's
    own compositor is set to the GPU (`compositor_device`, which a pipeline
    script may set on every scene). The add-on's scenes composite nothing:
    theirs stays on the CPU."""
    if hasattr(own_scene.render, "compositor_device"):
        set_if_different(own_scene.render, "compositor_device", "CPU")


def copy(scene, helper):
    """Only plain values: allowed in the render job's thread too."""
    keep_compositor_on_cpu(helper)
    for layer in helper.view_layers:  # saved off (saved_switch.py)
        set_if_different(layer, "use", True)
    for attribute in SYNCED_RENDER_SETTINGS:
        set_if_different(helper.render, attribute, getattr(scene.render, attribute))
    for view in scene.render.views:
        own = helper.render.views.get(view.name)
        if own is not None:
            for attribute in VIEW_SETTINGS:
                set_if_different(own, attribute, getattr(view, attribute))


def copy_views(scene, helper):
    """The helper's views made the main scene's: added, and those the main
    scene lacks removed (left and right, which Blender keeps, switched off).
    Main thread only: it adds and removes data."""
    views = helper.render.views
    for view in scene.render.views:
        if views.get(view.name) is None:
            views.new(view.name)
    for own in list(views):
        if scene.render.views.get(own.name) is None:
            try:
                views.remove(own)
            except RuntimeError:  # Blender's stereo views cannot go
                set_if_different(own, "use", False)
    copy(scene, helper)
