# SPDX-License-Identifier: GPL-2.0-or-later
"""The views of a stereo or multi-view render, and the camera of each.

Blender renders a view of Stereo 3D through the scene camera moved to that
eye (its Stereoscopy settings: interocular distance, convergence, pivot),
which its render engines ask for with RenderEngine.camera_model_matrix and
camera_shift_x once the view is active; a view of Multi-View through the
camera whose name has the view's camera suffix in place of another view's
(Camera_L for "left" when the scene camera is Camera_C), or the scene camera
where the scene has no such object."""
import bpy

from . import camera as camera_model
from . import strip_cameras
from .extra_renders import EXTRA_KEY
from .helper_lookup import is_helper


def rendered_views(scene):
    """[(view name, file suffix)] of the views Blender renders for `scene`,
    in its order; None for a render without Stereoscopy."""
    render = scene.render
    if not render.use_multiview:
        return None
    stereo = render.views_format == "STEREO_3D"
    return [(view.name, view.file_suffix) for view in render.views
            if view.use and (not stereo or view.name in ("left", "right"))]


def multiview_camera(scene, camera, view_name):
    """The object a Multi-View `view_name` renders through: `camera`'s name
    with the longest view camera suffix that ends it (the last of equal
    length) replaced by this view's, where `scene` has that object."""
    name = camera.name
    stem = None
    longest = -1
    for view in scene.render.views:
        suffix = view.camera_suffix
        if longest <= len(suffix) <= len(name) and name.endswith(suffix):
            stem, longest = name[:len(name) - len(suffix)], len(suffix)
    if stem is None:
        return camera
    found = scene.objects.get(stem + scene.render.views[view_name].camera_suffix)
    return found if found is not None else camera


def view_cameras(scene, camera):
    """The objects the views of `scene` render through besides `camera`
    (Multi-View's own cameras; the helper links them, so that its depsgraph
    evaluates their animation)."""
    views = rendered_views(scene)
    if camera is None or not views or scene.render.views_format != "MULTIVIEW":
        return []
    found = [multiview_camera(scene, camera, name) for name, _suffix in views]
    return [obj for obj in found if obj != camera]


def render_cameras(scenes):
    """The cameras `scenes` render through: their own, the Camera overrides
    of sequencer strips that show them, and the views' own cameras of each
    (the helper links them all, so that its depsgraph evaluates their
    animation)."""
    cameras = [scene.camera for scene in scenes] + strip_cameras.strip_overrides(scenes)
    for scene in scenes:
        for camera in list(cameras):
            cameras += view_cameras(scene, camera)
    unique = []
    for camera in cameras:
        if camera is not None and camera not in unique:
            unique.append(camera)
    return unique


# The camera a helper renders through where its main scene has none, and
# the ID property that marks it as the add-on's (an artist's object may have
# the name: then it was taken for the stand-in, and a new one made at every
# sync; a review).
STAND_IN_CAMERA_NAME = ".HBAO stand-in camera"
STAND_IN_KEY = "hbao_stand_in"


def stand_in_camera(tree):
    """A camera for the helper of a scene without one (a scene that only
    composites other scenes' renders): Blender refuses to render a scene
    without a camera ("Cannot render, no camera"), the helper too, and that
    cancelled the whole render. That of an artist's scene a Render Layers
    node of `tree` shows (not one of the add-on's scenes, whose cameras it
    removes), else one made for it (drop_unused_stand_in removes it with
    the helper). Main thread only."""
    for node in tree.nodes:
        scene = node.scene if node.bl_idname == "CompositorNodeRLayers" else None
        if scene is not None and scene.camera is not None and not is_helper(scene) and \
                EXTRA_KEY not in scene.keys():
            return scene.camera
    stand_in = _stand_in()
    if stand_in is None:
        stand_in = bpy.data.objects.new(STAND_IN_CAMERA_NAME,
                                        bpy.data.cameras.new(STAND_IN_CAMERA_NAME))
        stand_in[STAND_IN_KEY] = True
    return stand_in


def _stand_in():
    """The add-on's stand-in camera object of this file, or None."""
    def ours(obj):
        return obj is not None and obj.library is None and obj.type == "CAMERA" and \
            bool(obj.get(STAND_IN_KEY))
    named = bpy.data.objects.get(STAND_IN_CAMERA_NAME)
    if ours(named) or named is None:
        return named
    return next((obj for obj in bpy.data.objects if ours(obj)), None)


def drop_unused_stand_in():
    """Remove the stand-in camera once no helper holds it, its camera data
    too: an object nobody uses leaves the file, but its data stayed."""
    stand_in = _stand_in()
    if stand_in is None or stand_in.users != 0:
        return
    data = stand_in.data
    bpy.data.objects.remove(stand_in)
    if data is not None and data.users == 0:
        bpy.data.cameras.remove(data)


def camera_of_view(engine, scene, camera, view_name, evaluated=lambda obj: obj):
    """camera.camera_for_render_result() of view `view_name` of `scene`'s
    render through `camera` (an evaluated copy); `engine`: the render engine
    that renders now, `evaluated(obj)`: the evaluated copy of another
    camera object."""
    if scene.render.views_format == "MULTIVIEW":
        return camera_model.camera_for_render_result(
            scene, evaluated(multiview_camera(scene, camera.original, view_name)))
    engine.active_view_set(view_name)
    description = camera_model.camera_from_blender(scene, camera)
    to_world = engine.camera_model_matrix(camera, use_spherical_stereo=False)
    description["world_to_camera"] = [[float(v) for v in row]
                                      for row in to_world.inverted_safe()]
    description["shift_x"] = float(engine.camera_shift_x(camera, use_spherical_stereo=False))
    return camera_model.camera_for_render_result(scene, description=description)
