# SPDX-License-Identifier: GPL-2.0-or-later
"""The scene camera as the camera dict native.compute_ao() takes."""


class CameraError(ValueError):
    """The scene has no camera the library can model."""


def camera_from_blender(scene, camera_object=None):
    """Blender's camera model of `scene` (its camera, or `camera_object`,
    which may be an evaluated copy) with Blender's property names."""
    camera_object = camera_object or scene.camera
    if camera_object is None:
        raise CameraError(f"scene {scene.name!r} has no camera")
    camera = camera_object.data
    if getattr(camera, "type", None) not in ("PERSP", "ORTHO"):
        kind = getattr(camera, "type", "not a camera")
        raise CameraError(f"camera {camera_object.name!r} is {kind}: HBAO supports "
                          f"perspective and orthographic cameras")
    world_to_camera = camera_object.matrix_world.inverted_safe()
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
    }


def render_size(scene):
    """(width, height) in pixels of the scene's Render Result: resolution times
    percentage, cropped to the border when the border is cropped."""
    render = scene.render
    scale = render.resolution_percentage / 100.0
    width = int(render.resolution_x * scale)
    height = int(render.resolution_y * scale)
    if render.use_border and render.use_crop_to_border:
        x0, x1, y0, y1 = _border_pixels(render, width, height)
        return x1 - x0, y1 - y0
    return width, height


def _border_pixels(render, width, height):
    # Blender rounds the border to whole pixels the same way (rcti from rctf).
    x0 = int(render.border_min_x * width)
    x1 = int(render.border_max_x * width)
    y0 = int(render.border_min_y * height)
    y1 = int(render.border_max_y * height)
    return x0, max(x1, x0 + 1), y0, max(y1, y0 + 1)


def sensor_fit(camera, width, height):
    """Blender's sensor-fit rule (BKE_camera_params_compute_viewplane) for a
    camera dict on a `width` x `height` image: (fitted axis "HORIZONTAL" or
    "VERTICAL", the sensor size in mm (or ortho scale's side) spanning it, and
    that side's length in pixel widths). AUTO fits the larger side of the
    aspect-corrected image, with sensor_width whichever side that is. The C
    library (csrc/lib/camera.c) and this function are the rule's two
    implementations; tests/test_viewport_projection.py ties the Python uses
    of it together."""
    aspect_x = float(camera.get("pixel_aspect_x", 1.0))
    aspect_y = float(camera.get("pixel_aspect_y", 1.0))
    requested = camera.get("sensor_fit", "AUTO")
    fit = requested
    if fit == "AUTO":
        fit = "HORIZONTAL" if aspect_x * width >= aspect_y * height else "VERTICAL"
    sensor = float(camera.get("sensor_height", 24.0)) if requested == "VERTICAL" \
        else float(camera.get("sensor_width", 36.0))
    fitted_side = width if fit == "HORIZONTAL" else aspect_y / aspect_x * height
    return fit, sensor, fitted_side


def crop_camera(description, width, height, border):
    """The camera dict of the `border` (x0, x1, y0, y1 pixels, y from the
    bottom) of a `width` x `height` image seen by camera dict `description`:
    same focal length in pixels, the principal point moved by a lens shift,
    the sensor fitted horizontally to the crop."""
    x0, x1, y0, y1 = border
    _fit, sensor, fitted_side = sensor_fit(description, width, height)
    ycor = float(description.get("pixel_aspect_y", 1.0)) / \
        float(description.get("pixel_aspect_x", 1.0))
    crop_width = x1 - x0
    # The crop's centre relative to the full frame's, in pixel widths.
    dx = (x0 + x1) / 2.0 - width / 2.0
    dy = ((y0 + y1) / 2.0 - height / 2.0) * ycor
    cropped = dict(description)
    cropped["sensor_fit"] = "HORIZONTAL"
    cropped["sensor_width"] = sensor * crop_width / fitted_side
    cropped["ortho_scale"] = float(description.get("ortho_scale", 6.0)) * crop_width / fitted_side
    cropped["shift_x"] = (float(description.get("shift_x", 0.0)) * fitted_side + dx) / crop_width
    cropped["shift_y"] = (float(description.get("shift_y", 0.0)) * fitted_side + dy) / crop_width
    return cropped


def camera_for_render_result(scene, camera_object=None):
    """camera_from_blender(), turned into the camera of the cropped image
    (crop_camera) when the scene renders a cropped border."""
    description = camera_from_blender(scene, camera_object)
    render = scene.render
    if not (render.use_border and render.use_crop_to_border):
        return description
    scale = render.resolution_percentage / 100.0
    width, height = int(render.resolution_x * scale), int(render.resolution_y * scale)
    return crop_camera(description, width, height, _border_pixels(render, width, height))
