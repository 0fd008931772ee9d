# SPDX-License-Identifier: GPL-2.0-or-later
"""The node's guard band, as geometry (no bpy): occluders just outside the
frame, seen by an extra render through a wider camera.

Blender renders a scene that the compositor reads at the main render's size
(pipeline: "scene uses its own size (unfinished code)"), so the guard scene
cannot add pixels around the frame. Its camera instead widens the view by
`scale` about the frame's centre: the same pixel count covers `scale` times
the width and height, each guard pixel `scale` main pixels wide. Its depth
and normals are resampled onto the main pixel grid around the frame, and the
main render's own passes fill the frame itself, so that inside the frame
only the occluders outside it change the AO."""
import math

import numpy as np

from .parameters import MAX_IMAGE_SIZE

# The widest band the node offers, as a fraction of the frame's width (and
# height) on each side; the guard render then covers 1 + 2 x this.
MAX_GUARD_BAND = 0.25


def guard_scale(fraction):
    """How much wider the guard camera sees than the main one, for a band of
    `fraction` of the frame on each side."""
    return 1.0 + 2.0 * min(max(float(fraction), 0.0), MAX_GUARD_BAND)


def band_pixels(width, height, fraction):
    """(columns, rows) of the band on each side of a width x height frame;
    whole pixels inside what the guard render covers, and no more than keeps
    the frame with its bands within the library's largest image (a frame
    43692 pixels wide with a 25 % band lost its whole AO to the library's
    size check; an exploratory run)."""
    fraction = min(max(float(fraction), 0.0), MAX_GUARD_BAND)

    def side(size):
        return max(0, min(int(math.floor(fraction * size)), (MAX_IMAGE_SIZE - size) // 2))
    return side(width), side(height)


def widened_camera(values, scale):
    """The guard camera's settings from the main camera's (Blender's property
    names): the view plane `scale` times as wide and tall about the same
    centre. Sensor sizes and the orthographic scale grow; shifts, in units of
    the view's size, shrink so that the view's offset stays."""
    widened = dict(values)
    for name in ("sensor_width", "sensor_height", "ortho_scale"):
        widened[name] = values[name] * scale
    for name in ("shift_x", "shift_y"):
        widened[name] = values[name] / scale
    return widened


def _guard_indices(count, band, scale):
    """For main-grid positions -band .. count + band - 1 along one axis, the
    guard pixel whose area holds each position's centre."""
    centres = np.arange(-band, count + band, dtype=np.float64) + 0.5
    guard = np.floor((centres - count / 2.0) / scale + count / 2.0).astype(np.int64)
    return np.clip(guard, 0, count - 1)


def extend(main, guard, band, scale):
    """The main pass (H, W[, C]) with a band of (columns, rows) around it taken
    from the guard render's pass of the same shape (nearest guard pixel).
    Rows run the same way in both (top-down EXR rows or bottom-up passes)."""
    height, width = main.shape[:2]
    if guard.shape != main.shape:
        raise ValueError(f"the guard render is {guard.shape[1]}x{guard.shape[0]}, the render "
                         f"{width}x{height}")
    columns, rows = band
    extended = guard[_guard_indices(height, rows, scale)[:, None],
                     _guard_indices(width, columns, scale)[None, :]]
    extended[rows:rows + height, columns:columns + width] = main
    return extended


def crop_band(extended, band):
    """The frame's part of an extended image."""
    columns, rows = band
    height = extended.shape[0] - 2 * rows
    width = extended.shape[1] - 2 * columns
    return extended[rows:rows + height, columns:columns + width]
