# SPDX-License-Identifier: GPL-2.0-or-later
"""Runs inside Blender with a window (xvfb) and the hbao add-on enabled: builds
the demo scene, looks through its camera in Solid shading in a 3D view filling
the window, and takes three screenshots of that view: before the preview was
ever on, with it on (kept as the artifact for people to look at), and after it
was turned off again; then two of a user's orthographic view, without and with
the preview. Writes what it saw as JSON for tests/test_viewport.py.

    blender --factory-startup --addons hbao --python viewport_toggle.py -- OUT.json SHOT.png
"""
import json
import sys
import traceback
from pathlib import Path

import bpy
import numpy as np
from mathutils import Euler, Vector

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "scripts"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import blender_scenes  # noqa: E402
import timer_guard  # noqa: E402

# The preview of a 3D view is switched by its operator, as the panel does.
TOGGLE = "hbao.viewport_preview_toggle"
# Strong enough to see in a screenshot; the demo scene's props are ~1 m.
PREVIEW_SETTINGS = {"radius": 0.6, "strength": 1.5}


def arguments():
    args = sys.argv[sys.argv.index("--") + 1:]
    return Path(args[0]), Path(args[1])


def view_3d(window):
    return max((a for a in window.screen.areas if a.type == "VIEW_3D"),
               key=lambda a: a.width * a.height)


def window_region(area):
    return next(r for r in area.regions if r.type == "WINDOW")


def override(window, area):
    return bpy.context.temp_override(window=window, screen=window.screen, area=area,
                                     region=window_region(area))


def redraw(window, area):
    with override(window, area):
        bpy.ops.wm.redraw_timer(type="DRAW_WIN_SWAP", iterations=2)


def screenshot(window, area, path):
    redraw(window, area)
    with override(window, area):
        bpy.ops.screen.screenshot_area(filepath=str(path), check_existing=False)
    image = bpy.data.images.load(str(path), check_existing=False)
    pixels = np.empty(image.size[0] * image.size[1] * image.channels, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    shape = (image.size[1], image.size[0], image.channels)
    bpy.data.images.remove(image)
    return pixels.reshape(shape)[..., :3]


def run():
    out_path, shot_path = arguments()
    viewport = sys.modules["hbao.viewport"]
    draw = sys.modules["hbao.viewport.draw"]
    view_settings_module = sys.modules["hbao.viewport.view_entries"]

    window = bpy.context.window_manager.windows[0]
    blender_scenes.build_demo_scene(bpy.context.scene)
    # The preview turned on in the layout's view, which is then maximized
    # (its space moves into a temporary screen): it keeps its settings there.
    home_area = view_3d(window)
    with override(window, home_area):
        bpy.ops.hbao.viewport_preview_toggle()
    home = view_settings_module.find(window.screen, home_area)
    with override(window, home_area):
        bpy.ops.screen.screen_full_area(use_hide_panels=True)
    area = view_3d(window)
    maximized = view_settings_module.find(window.screen, area)
    report_start = {"maximized_keeps_settings": window.screen.name.endswith("-nonnormal") and
                    maximized is not None and maximized.as_pointer() == home.as_pointer() and
                    maximized.enabled}
    with override(window, area):
        bpy.ops.hbao.viewport_preview_toggle()  # off again: the rest starts from "never on"
    space = area.spaces.active
    space.shading.type = "SOLID"
    space.overlay.show_overlays = False
    space.show_gizmo = False
    space.region_3d.view_perspective = "CAMERA"
    with override(window, area):
        bpy.ops.view3d.view_center_camera()

    report = {"registered_add_on_viewport": viewport.is_registered(),
              "handler_before": draw.handler_registered(), **report_start}
    before = screenshot(window, area, shot_path.with_name("viewport_never_on.png"))

    with override(window, area):
        bpy.ops.hbao.viewport_preview_toggle()
    view_settings = view_settings_module.find(window.screen, area)
    for name, value in PREVIEW_SETTINGS.items():
        setattr(view_settings, name, value)
    report["handler_on"] = draw.handler_registered()
    report["enabled_on"] = view_settings.enabled
    on = screenshot(window, area, shot_path)

    with override(window, area):
        bpy.ops.hbao.viewport_preview_toggle()
    report["handler_after"] = draw.handler_registered()
    report["enabled_after"] = view_settings.enabled
    after = screenshot(window, area, shot_path.with_name("viewport_turned_off.png"))

    luminance_before = before.mean(axis=2)
    luminance_on = on.mean(axis=2)
    report.update({
        "size": list(before.shape[:2]),
        "off_vs_never_max_abs": float(np.abs(after - before).max()),
        "on_vs_never_mean": float((luminance_before - luminance_on).mean()),
        "darkened_fraction": float((luminance_on < luminance_before - 2.0 / 255.0).mean()),
        "brightened_fraction": float((luminance_on > luminance_before + 1.0 / 255.0).mean()),
        "preview_errors": sorted(draw._reported_errors),
    })
    user_orthographic(window, area, report, shot_path)
    tiny_clip_start(window, area, report, shot_path)
    turned_on_while_maximized(window, area, report)
    print(json.dumps(report, indent=2))
    out_path.write_text(json.dumps(report, indent=2))


def user_orthographic(window, area, report, shot_path):
    """A user's orthographic view (numpad 5), not the camera's: it clips about
    its pivot, so depths in front of the pivot are negative from it. The
    preview darkens it as it does the camera's view."""
    region = area.spaces.active.region_3d
    region.view_perspective = "ORTHO"
    rotation = Euler((1.05, 0.0, 0.3)).to_quaternion()
    region.view_rotation = rotation
    # the pivot 8 units beyond the props, so that all of them lie in front of it
    region.view_location = Vector((0.0, 0.0, 0.5)) + 8.0 * (rotation @ Vector((0.0, 0.0, -1.0)))
    region.view_distance = 6.0
    off = screenshot(window, area, shot_path.with_name("viewport_ortho_off.png"))
    with override(window, area):
        bpy.ops.hbao.viewport_preview_toggle()
    on = screenshot(window, area, shot_path.with_name("viewport_hbao_ortho.png"))
    with override(window, area):
        bpy.ops.hbao.viewport_preview_toggle()
    darker = on.mean(axis=2) < off.mean(axis=2) - 2.0 / 255.0
    report["ortho_darkened_fraction"] = float(darker.mean())
    region.view_perspective = "CAMERA"


def tiny_clip_start(window, area, report, shot_path):
    """The camera's view with Clip Start 0.001 and Clip End 10000: the depth
    buffer's steps are then a thousandth of the depth at 10 units, and the
    preview took them for bumps (streaks of false occlusion on the floor).
    The preview's darkening is measured as with the default clip range."""
    camera = bpy.context.scene.camera.data
    clip = camera.clip_start, camera.clip_end
    darkened = {}
    for name, (start, end) in (("default", clip), ("tiny", (0.001, 10000.0))):
        camera.clip_start, camera.clip_end = start, end
        off = screenshot(window, area, shot_path.with_name(f"viewport_clip_{name}_off.png"))
        with override(window, area):
            bpy.ops.hbao.viewport_preview_toggle()
        on = screenshot(window, area, shot_path.with_name(f"viewport_clip_{name}.png"))
        with override(window, area):
            bpy.ops.hbao.viewport_preview_toggle()
        darkened[name] = float((on.mean(axis=2) < off.mean(axis=2) - 2.0 / 255.0).mean())
    camera.clip_start, camera.clip_end = clip
    report["clip_default_darkened_fraction"] = darkened["default"]
    report["clip_tiny_darkened_fraction"] = darkened["tiny"]


def turned_on_while_maximized(window, area, report):
    """A view that never had the preview, turned on while maximized: on
    return to its layout the view keeps it (its settings are made on the
    home screen, in the place the view comes back to)."""
    with override(window, area):
        bpy.ops.screen.back_to_previous()
    home = window.screen
    # a fresh 3D view: the timeline's area turned into one
    fresh = next(a for a in home.areas if a.type == "DOPESHEET_EDITOR")
    fresh.type = "VIEW_3D"
    view_settings_module = sys.modules["hbao.viewport.view_entries"]
    report["fresh_view_had_settings"] = view_settings_module.find(home, fresh) is not None
    with override(window, fresh):
        bpy.ops.screen.screen_full_area(use_hide_panels=False)
    maximized = view_3d(window)
    with override(window, maximized):
        bpy.ops.hbao.viewport_preview_toggle()
    on = view_settings_module.find(window.screen, maximized)
    report["fresh_on_while_maximized"] = on is not None and on.enabled
    with override(window, maximized):
        bpy.ops.screen.back_to_previous()
    back = view_settings_module.find(window.screen, fresh)
    report["fresh_back_home"] = window.screen == home
    report["fresh_keeps_preview_at_home"] = back is not None and back.enabled
    report["fresh_is_another_entry"] = back is not None and back.name != \
        view_settings_module.find(home, view_3d_other(home, fresh)).name


def view_3d_other(screen, besides):
    return next(a for a in screen.areas if a.type == "VIEW_3D" and a != besides)


def step():
    # Blender 3.4 crashes (in its own code, without this add-on too) when the
    # event loop runs again after screen_full_area from a timer: everything
    # happens in this one call, which ends Blender at once (a scheduled quit
    # can wait a pass of the event loop: timer_guard.end_now).
    try:
        run()
    except BaseException:  # SystemExit too: the event loop must not run again
        print("SCRIPT ERROR:", traceback.format_exc(), sep="\n", flush=True)
        timer_guard.end_now(1)
    timer_guard.end_now(0)


# The window exists only once the event loop runs: start from a timer.
timer_guard.guarded_timer(step, 0.5)
