# SPDX-License-Identifier: GPL-2.0-or-later
"""The scene camera as the camera dict native.compute_ao() takes."""
import numpy as np

from . import native


# CameraError.camera_name of an error about no one camera (strips that
# disagree): no scene camera's name.
NOT_ONE_CAMERA = object()


class CameraError(ValueError):
    """The scene has no camera the library can model; `short`: the form
    that fits the node's status line; `camera_name`: the camera it is about
    (None: there is none)."""

    def __init__(self, message, short="Camera: AO off", camera_name=NOT_ONE_CAMERA):
        super().__init__(message)
        self.short = short
        self.camera_name = camera_name


# A status line's cause (report.NodeMessage): the scene's own camera is one
# the library cannot model (status_causes.py checks it again).
SCENE_CAMERA_CAUSE = ("scene camera",)


def scene_camera_cause(scene, error):
    """SCENE_CAMERA_CAUSE where CameraError `error` is about `scene`'s own
    camera (not a sequencer strip's or a stereo view's), else None."""
    own = scene.camera.name if scene.camera is not None else None
    return SCENE_CAMERA_CAUSE if error.camera_name == own else None


def scene_camera_fails(scene):
    """Whether the library cannot model `scene`'s own camera now."""
    try:
        camera_from_blender(scene)
    except CameraError:
        return True
    return False


# Blender's camera types that the library does not model, as artists name them
_CAMERA_KINDS = {"PANO": "panoramic"}


def camera_from_blender(scene, camera_object=None):
    """Blender's camera model of `scene` (its camera, or `camera_object`,
    which may be an evaluated copy) with Blender's property names."""
    camera_object = camera_object or scene.camera
    if camera_object is None:
        raise CameraError(f"scene {scene.name!r} has no camera", "No camera: AO off", None)
    camera = camera_object.data
    if getattr(camera, "type", None) not in ("PERSP", "ORTHO"):
        kind = getattr(camera, "type", None)
        if kind is None:
            raise CameraError(f"the scene's camera {camera_object.name!r} is not a camera",
                              camera_name=camera_object.name)
        kind = _CAMERA_KINDS.get(kind, str(kind).lower())
        raise CameraError(f"camera {camera_object.name!r} is {kind}: HBAO supports "
                          f"perspective and orthographic cameras (Camera properties > Lens > "
                          f"Type)", f"{kind.capitalize()} camera: AO off", camera_object.name)
    to_world = model_matrix(camera_object.matrix_world)
    if shear(to_world) > SHEAR_TOLERANCE:
        raise CameraError(
            f"camera {camera_object.name!r} is sheared (its matrix's axes are not square: a "
            f"parent scaled unevenly with the camera turned inside it, or a constraint): "
            f"Blender renders a sheared view, which HBAO does not model. Apply the parent's "
            f"scale (Object > Apply > Scale) or scale it evenly", "Sheared camera: AO off",
            camera_object.name)
    world_to_camera = to_world.inverted_safe()
    render = scene.render
    return {
        "type": camera.type,
        "lens": float(camera.lens),
        "sensor_width": float(camera.sensor_width),
        "sensor_height": float(camera.sensor_height),
        "sensor_fit": camera.sensor_fit,
        "shift_x": float(camera.shift_x),
        "shift_y": float(camera.shift_y),
        "ortho_scale": float(camera.ortho_scale),
        "pixel_aspect_x": float(render.pixel_aspect_x),
        "pixel_aspect_y": float(render.pixel_aspect_y),
        "world_to_camera": [[float(v) for v in row] for row in world_to_camera],
        "clip_start": float(camera.clip_start),
        "clip_end": float(camera.clip_end),
    }


def model_matrix(matrix_world):
    """A camera object's matrix as Blender renders through it: each axis of
    unit length (BKE_camera_multiview_model_matrix normalises them), so a
    scaled camera, or one whose parent is scaled, renders as unscaled. The
    library turns the Normal pass by this matrix's inverse: with the scale
    left in, a camera scaled unevenly turned the normals askew (AO off by up
    to 0.3, silently)."""
    matrix = matrix_world.copy()
    for axis in range(3):
        length = matrix.col[axis].xyz.length
        if length > 0.0:
            for row in range(3):
                matrix[row][axis] /= length
    return matrix


# Blender keeps a camera's axes as its matrix has them, made unit length but
# not perpendicular: under a parent scaled unevenly, a turned camera renders
# a sheared view, whose AO the library's pinhole camera does not give (0.15 to
# 0.26 off for parents scaled (1, 1.6, 0.7) and (1, 2.5, 0.5), against the
# sheared view's true geometry: found by an exploratory run). Below this
# cosine between two axes (0.06 degrees off square) the error is far under
# what a viewer sees; above it the AO is off, and the camera error says why.
SHEAR_TOLERANCE = 1e-3


def shear(matrix):
    """The largest |cosine| between two axes of a model_matrix()."""
    axes = [matrix.col[axis].xyz for axis in range(3)]
    return max(abs(axes[0].dot(axes[1])), abs(axes[0].dot(axes[2])), abs(axes[1].dot(axes[2])))


def background_depth(description, depth):
    """The background depth for a render through camera dict `description`:
    libhbao's rule (hbao_clip_background_depth) for its Clip Start and End,
    or `depth` (the parameter's) where it has none. EEVEE in 4.5 and 5.0
    writes the sky's Depth as Clip End or a rounding of it, where 3.4 writes
    65504 (background at any background depth) and 5.3 1e10."""
    return native.clip_background_depth(description.get("clip_start"),
                                        description.get("clip_end"), depth)


def full_size(render):
    """(width, height) in pixels of the whole image `render` (a scene's
    RenderSettings) renders: resolution times percentage in integers, as
    Blender's BKE_render_resolution (in floats, 200 at 58 % gave 115, not
    116: a cropped border's camera was then worked out on the wrong size)."""
    percentage = render.resolution_percentage
    return render.resolution_x * percentage // 100, render.resolution_y * percentage // 100


def render_size(scene):
    """(width, height) in pixels of the scene's Render Result: full_size(),
    cropped to the border when the border is cropped."""
    render = scene.render
    width, height = full_size(render)
    if render.use_border and render.use_crop_to_border:
        x0, x1, y0, y1 = _border_pixels(render, width, height)
        return x1 - x0, y1 - y0
    return width, height


def uncropped_border(scene, full_size, region_size):
    """(x0, x1, y0, y1) pixels (y from the bottom) of the scene's border in
    its full Render Result of full_size (height, width), when the scene
    renders a border without cropping and the border's size is region_size
    (height, width): what a helper scene's result holds then. Else None."""
    render = scene.render
    if not render.use_border or render.use_crop_to_border:
        return None
    height, width = full_size
    border = _border_pixels(render, width, height)
    x0, x1, y0, y1 = border
    return border if (y1 - y0, x1 - x0) == tuple(region_size) else None


def _border_edge(fraction, size):
    """Blender's pixel of a border edge: the float border times the int size
    in float (single precision), truncated. In double precision 0.7 x 10
    gives 6 where Blender has 7, and 0.01 x 100 gives 0 where it has 1."""
    return int(np.float32(fraction) * np.float32(size))


def _border_pixels(render, width, height):
    x0 = _border_edge(render.border_min_x, width)
    x1 = _border_edge(render.border_max_x, width)
    y0 = _border_edge(render.border_min_y, height)
    y1 = _border_edge(render.border_max_y, height)
    return x0, max(x1, x0 + 1), y0, max(y1, y0 + 1)


def crop_camera(description, width, height, border):
    """The camera dict of the `border` (x0, x1, y0, y1 pixels, y from the
    bottom) of a `width` x `height` image seen by camera dict `description`:
    the same view rays, by libhbao's crop rule (native.camera_crop), which
    the CLI applies to EXR data windows too. Raises native's errors."""
    x0, x1, y0, y1 = border
    return native.camera_crop(description, width, height, x0, height - y1, x1 - x0, y1 - y0)


def camera_for_render_result(scene, camera_object=None, description=None):
    """camera_from_blender() (or `description`, a view's), turned into the
    camera of the cropped image (crop_camera) when the scene renders a
    cropped border."""
    if description is None:
        description = camera_from_blender(scene, camera_object)
    render = scene.render
    if not (render.use_border and render.use_crop_to_border):
        return description
    width, height = full_size(render)
    return crop_camera(description, width, height, _border_pixels(render, width, height))
