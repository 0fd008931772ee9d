# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in a Blender window (xvfb) by tests/test_viewport.py: the demo scene
through its camera in Solid shading with overlays on, every object selected
and none, the preview off and on. The selection outlines are the pixels
that differ between the two selections with the preview off; where the
preview darkens the unselected view under them (a crease), an outline
should keep its colour: the AO belongs to the scene, not to the overlays
(an exploratory run saw an outline across a crease turn near black).
Prints 'OVERLAYS {json}': how many such pixels, and how much the preview
darkens the scene there and the outlines there (means of RGB, 0-1).

  blender --factory-startup --addons hbao --python viewport_overlays.py -- OUT_DIR
"""
import json
import os
import sys

import bpy
import numpy as np

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


def select_all(selected):
    for obj in bpy.context.scene.objects:
        obj.select_set(selected and obj.type == "MESH")


def steps():
    blender_scenes.build_demo_scene(bpy.context.scene)
    _window, area = view_3d()
    space = area.spaces.active
    space.shading.type = "SOLID"
    space.overlay.show_overlays = True
    space.region_3d.view_perspective = "CAMERA"
    with override():
        bpy.ops.view3d.view_center_camera()
    shots = {}
    for preview in ("off", "on"):
        if preview == "on":
            with override():
                bpy.ops.hbao.viewport_preview_toggle()
            view_settings = sys.modules["hbao.viewport.view_entries"].find(area.id_data, area)
            # strong enough to see in a screenshot (as viewport_toggle.py)
            view_settings.radius, view_settings.strength = 0.6, 1.5
        for selection in ("selected", "unselected"):
            select_all(selection == "selected")
            shots[preview, selection] = shot(f"overlays_{preview}_{selection}")
            yield
    outline = np.abs(shots["off", "selected"] - shots["off", "unselected"]) > 0.08
    scene_darkening = shots["off", "unselected"] - shots["on", "unselected"]
    under = outline & (scene_darkening > 0.1)
    outline_darkening = shots["off", "selected"] - shots["on", "selected"]
    result = {
        "pixels": int(under.sum()),
        "scene": float(scene_darkening[under].mean()) if under.any() else 0.0,
        "outline": float(outline_darkening[under].mean()) if under.any() else 0.0,
    }
    print(f"OVERLAYS {json.dumps(result)}", flush=True)
    yield


walk = steps()


def tick():
    try:
        next(walk)
    except StopIteration:
        print("OVERLAYS: DONE", flush=True)
        timer_guard.quit_blender()
        return None
    return 0.3


timer_guard.guarded_timer(tick, 0.5)
