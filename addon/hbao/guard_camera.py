# SPDX-License-Identifier: GPL-2.0-or-later
"""The guard band render's camera (extra_renders.py): an object of its own
that follows the scene camera (a Copy Transforms constraint) and copies its
settings, its view widened about the frame's centre (guard_geometry.py)."""
import bpy

from . import guard_geometry, writes
from .data_edits import set_if_different

SETTINGS = ("type", "lens", "sensor_width", "sensor_height", "sensor_fit", "shift_x", "shift_y",
            "ortho_scale", "clip_start", "clip_end")


def copy_settings(main, guard, scale):
    """The guard scene's camera settings from `main`'s scene camera's,
    widened `scale` times. Plain values only: allowed in the render job's
    thread."""
    source = main.camera
    target = guard.camera
    if source is None or target is None or source.type != "CAMERA":
        return
    values = {name: getattr(source.data, name) for name in SETTINGS}
    widened = guard_geometry.widened_camera(values, scale)
    for name in SETTINGS:
        set_if_different(target.data, name, widened[name])
    set_if_different(target.data.dof, "use_dof", False)
    for name in ("pixel_aspect_x", "pixel_aspect_y"):
        set_if_different(guard.render, name, getattr(main.render, name))


def follow(main, guard, name):
    """The guard scene's camera (made, named `name`, where it has none of
    its own), following `main`'s scene camera. Main thread only."""
    camera = guard.camera
    if camera is None or camera == main.camera:
        data = bpy.data.cameras.new(name)
        camera = bpy.data.objects.new(name, data)

        def remove():
            bpy.data.objects.remove(camera)
            bpy.data.cameras.remove(data)
        with writes.whole_or_removed(remove):
            camera.constraints.new("COPY_TRANSFORMS")
            guard.camera = camera
    constraint = camera.constraints[0] if camera.constraints else None
    if constraint is not None and constraint.target != main.camera:
        constraint.target = main.camera
    return camera
