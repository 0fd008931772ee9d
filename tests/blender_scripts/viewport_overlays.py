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
import view_shots  # noqa: E402

out_dir = sys.argv[sys.argv.index("--") + 1]


def select_all(selected):
    for obj in bpy.context.scene.objects:
        obj.select_set(selected and obj.type == "MESH")


def steps():
    area, _space = view_shots.demo_in_solid(show_overlays=True)
    shots = {}
    for preview in ("off", "on"):
        if preview == "on":
            view_shots.preview_on(area)
        for selection in ("selected", "unselected"):
            select_all(selection == "selected")
            shots[preview, selection] = view_shots.shot(out_dir, f"overlays_{preview}_{selection}")
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


view_shots.walk_steps(steps(), "OVERLAYS")
