# SPDX-License-Identifier: GPL-2.0-or-later
"""A synthetic scene's planar depth, ray cast per pixel: no Blender, so that
the viewport preview's comparison with the library in Blender
(tests/blender_scripts/viewport_match.py) and its GPU benchmark without
Blender (scripts/bench_viewport_gl.py) draw the same scene."""
import numpy as np

# The perspective camera the scene is laid out for (a camera dict as
# native.compute_ao takes), with the clip range the viewport tests give
# Blender's camera.
CAMERA = {"type": "PERSP", "lens": 35.0, "sensor_width": 36.0, "sensor_height": 24.0,
          "sensor_fit": "AUTO", "clip_start": 0.1, "clip_end": 100.0}
# The floor's height (camera space) in the cases that do not give their own.
FLOOR_Y = -1.0


def synthetic_depth(frame, floor_y=FLOOR_Y):
    """Planar depth (top row first) of a floor at height `floor_y`, a back wall
    with sky above it, a box and a sphere, ray cast per pixel centre through
    `frame` (camera space, camera looking down -z)."""
    columns = frame.origin_x + (np.arange(frame.width) + 0.5) * frame.pixel_size_x
    rows = frame.origin_y + (frame.height - 1 - np.arange(frame.height) + 0.5) * frame.pixel_size_y
    x, y = np.meshgrid(columns, rows)
    if frame.perspective:
        # Ray through the pixel: (x, y, -1) t, t = planar depth.
        origin = np.stack([np.zeros_like(x), np.zeros_like(y), np.zeros_like(x)], -1)
        direction = np.stack([x, y, -np.ones_like(x)], -1)
    else:
        # Rays along -z from the image plane.
        origin = np.stack([x, y, np.zeros_like(x)], -1)
        direction = np.stack([np.zeros_like(x), np.zeros_like(y), -np.ones_like(x)], -1)
    depth = np.full(x.shape, np.inf)

    def hit(t):
        np.minimum(depth, np.where((t > 0) & np.isfinite(t), t, np.inf), out=depth)

    with np.errstate(divide="ignore", invalid="ignore"):
        if frame.perspective:
            # Floor y = floor_y up to z = -9, wall z = -9 up to y = 2.5, sky above.
            t = (floor_y - origin[..., 1]) / direction[..., 1]
            point = origin + direction * t[..., None]
            hit(np.where(point[..., 2] > -9.0, t, np.inf))
            t = (-9.0 - origin[..., 2]) / direction[..., 2]
            point = origin + direction * t[..., None]
            hit(np.where(point[..., 1] < 2.5, t, np.inf))
        else:
            # A gentle ramp that the box and the sphere stand in: creases all round.
            t = 4.4 + 0.15 * origin[..., 1]
            hit(np.where(origin[..., 1] < 2.0, t, np.inf))
        # Box (slab test).
        low = np.array([-1.6, -1.0, -5.2])
        high = np.array([-0.3, 0.1, -3.8])
        t1 = (low - origin) / direction
        t2 = (high - origin) / direction
        t_near = np.nanmax(np.minimum(t1, t2), axis=-1)
        t_far = np.nanmin(np.maximum(t1, t2), axis=-1)
        hit(np.where(t_near <= t_far, t_near, np.inf))
        # Sphere resting on the floor.
        centre = np.array([1.0, -0.4, -4.5])
        radius = 0.6
        oc = origin - centre
        a = np.sum(direction * direction, -1)
        b = 2.0 * np.sum(oc * direction, -1)
        c = np.sum(oc * oc, -1) - radius * radius
        disc = b * b - 4 * a * c
        hit(np.where(disc >= 0, (-b - np.sqrt(np.maximum(disc, 0))) / (2 * a), np.inf))
    # Blender's Cycles background.
    return np.where(np.isfinite(depth), depth, 1e10).astype(np.float32)
