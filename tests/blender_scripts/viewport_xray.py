# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in a Blender window (xvfb) by tests/test_viewport.py: the demo scene
through its camera in Solid shading with the preview on, with X-ray at
alpha 1 and at 0.5 (which writes no depth: an exploratory run saw the
preview draw nothing there, and the panel say nothing). For each alpha
prints 'XRAY <alpha> {json}': the fraction of the view's pixels the
preview darkens, and why the panel says it cannot draw (draw.not_drawn).

  blender --factory-startup --addons hbao --python viewport_xray.py -- OUT_DIR
"""
import json
import os
import sys

import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))), "scripts"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender_scenes  # noqa: E402
import timer_guard  # noqa: E402
import view_shots  # noqa: E402
from view_shots import override, view_3d  # noqa: E402

out_dir = sys.argv[sys.argv.index("--") + 1]


def shot(name):
    return view_shots.shot(os.path.join(out_dir, f"{name}.png"))


def steps():
    blender_scenes.build_demo_scene(bpy.context.scene)
    _window, area = view_3d()
    space = area.spaces.active
    space.shading.type = "SOLID"
    space.overlay.show_overlays = False
    space.region_3d.view_perspective = "CAMERA"
    with override():
        bpy.ops.view3d.view_center_camera()
    for alpha in (1.0, 0.5):
        space.shading.show_xray, space.shading.xray_alpha = True, alpha
        off = shot(f"xray_{int(alpha * 100)}_off")
        with override():
            bpy.ops.hbao.viewport_preview_toggle()
        view_settings = sys.modules["hbao.viewport.view_entries"].find(area.id_data, area)
        # strong enough to see in a screenshot (as viewport_toggle.py)
        view_settings.radius, view_settings.strength = 0.6, 1.5
        on = shot(f"xray_{int(alpha * 100)}_on")
        with override():
            bpy.ops.hbao.viewport_preview_toggle()
        why = sys.modules["hbao.viewport.draw"].not_drawn(space)
        darkened = float((on < off - 2.0 / 255.0).mean())
        print(f"XRAY {alpha} {json.dumps({'darkened': darkened, 'not_drawn': why})}",
              flush=True)
    yield


walk = steps()


def tick():
    try:
        next(walk)
    except StopIteration:
        print("XRAY: DONE", flush=True)
        timer_guard.quit_blender()
        return None
    return 0.3


timer_guard.guarded_timer(tick, 0.5)
