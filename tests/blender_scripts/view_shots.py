# SPDX-License-Identifier: GPL-2.0-or-later
"""What the viewport scripts that compare screenshots of the preview share
(a Blender window under xvfb): the largest 3D view (view_3d, override: a
context for its operators), the demo scene through its camera in Solid
shading (demo_in_solid), the preview turned on strong enough to see
(preview_on), screenshots as rows of per-pixel RGB means (shot), and the
scripts' steps walked from a timer (walk_steps). The caller has put
scripts/ and this folder on sys.path."""
import os
import sys

import bpy
import numpy as np

import blender_scenes
import timer_guard


def view_3d():
    window = bpy.context.window_manager.windows[0]
    return window, max((a for a in window.screen.areas if a.type == "VIEW_3D"),
                       key=lambda a: a.width * a.height)


def override():
    window, area = view_3d()
    region = [r for r in area.regions if r.type == "WINDOW"][-1]
    return bpy.context.temp_override(window=window, screen=window.screen, area=area,
                                     region=region)


def demo_in_solid(show_overlays):
    """The demo scene in the largest 3D view, through its camera, in Solid
    shading. Returns the view's area and space."""
    blender_scenes.build_demo_scene(bpy.context.scene)
    _window, area = view_3d()
    space = area.spaces.active
    space.shading.type = "SOLID"
    space.overlay.show_overlays = show_overlays
    space.region_3d.view_perspective = "CAMERA"
    with override():
        bpy.ops.view3d.view_center_camera()
    return area, space


def toggle_preview():
    with override():
        bpy.ops.hbao.viewport_preview_toggle()


def preview_on(area):
    """Turns the preview on in `area`, strong enough to see in a screenshot
    (as viewport_toggle.py)."""
    toggle_preview()
    view_settings = sys.modules["hbao.viewport.view_entries"].find(area.id_data, area)
    view_settings.radius, view_settings.strength = 0.6, 1.5


def shot(out_dir, name):
    """The view redrawn, saved as OUT_DIR/NAME.png, as a row of per-pixel
    RGB means."""
    path = os.path.join(out_dir, f"{name}.png")
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


def walk_steps(steps, label):
    """timer_guard.walk_steps: a step per timer tick, then 'LABEL: DONE'."""
    timer_guard.walk_steps(steps, label)
