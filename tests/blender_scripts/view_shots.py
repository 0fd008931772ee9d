# SPDX-License-Identifier: GPL-2.0-or-later
"""Screenshots of the largest 3D view of a Blender window (xvfb), for the
viewport scripts that compare what the preview draws: view_3d(),
override() (a context for that view's operators) and shot(path) (the view
redrawn, saved to path, returned as a row of per-pixel RGB means)."""
import bpy
import numpy as np


def view_3d():
    window = bpy.context.window_manager.windows[0]
    return window, max((a for a in window.screen.areas if a.type == "VIEW_3D"),
                       key=lambda a: a.width * a.height)


def override():
    window, area = view_3d()
    region = [r for r in area.regions if r.type == "WINDOW"][-1]
    return bpy.context.temp_override(window=window, screen=window.screen, area=area,
                                     region=region)


def shot(path):
    # the redraw and the screenshot each need their own override block
    with override():
        bpy.ops.wm.redraw_timer(type="DRAW_WIN_SWAP", iterations=2)
    with override():
        bpy.ops.screen.screenshot_area(filepath=path, check_existing=False)
    image = bpy.data.images.load(path, check_existing=False)
    pixels = np.empty(image.size[0] * image.size[1] * image.channels, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    channels = image.channels
    bpy.data.images.remove(image)
    return pixels.reshape(-1, channels)[:, :3].mean(axis=1)
