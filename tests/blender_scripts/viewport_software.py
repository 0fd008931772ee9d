# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in a Blender window (xvfb, so Mesa's software renderer) by
tests/test_viewport.py: the demo scene through its camera in Solid shading
with the preview on, drawn three times at full and three at half
resolution, taking turns, then once through X-ray at alpha 0.5 (which the preview cannot
draw). Prints 'SOFTWARE {json}': whether Blender draws with a software
renderer, the view's size, the preview's frame times that draw.py kept
after each draw, and the panel's note (panel.software_note) after the last
of each, and through X-ray. (3.4 gives Python no way to open the
sidebar's HBAO tab, so the panel itself is not drawn.)

  blender --factory-startup --addons hbao --python viewport_software.py -- OUT_DIR
"""
import json
import os
import sys

import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))), "scripts"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import view_shots  # noqa: E402

out_dir = sys.argv[sys.argv.index("--") + 1]
SHOTS = 3


def steps():
    draw = sys.modules["hbao.viewport.draw"]
    panel = sys.modules["hbao.viewport.panel"]
    area, space = view_shots.demo_in_solid(show_overlays=False)
    view_shots.preview_on(area)
    yield
    view_settings = sys.modules["hbao.viewport.view_entries"].find(area.id_data, area)
    region = next(region for region in area.regions if region.type == "WINDOW")
    report = {"software": draw.software_renderer(), "size": [region.width, region.height]}

    def note():
        return panel.software_note(area, view_settings, bpy.context.scene)

    # Full and half resolution take turns, so that a busy neighbour (the
    # other pytest worker) slows both alike; each shot draws twice, and
    # frame_ms is the second draw's, after the targets were made.
    report["full_ms"], report["half_ms"] = [], []
    for shot in range(SHOTS):
        for half in (False, True):
            view_settings.half_resolution = half
            name = "half" if half else "full"
            view_shots.shot(out_dir, f"software_{int(half)}_{shot}")
            report[f"{name}_ms"].append(draw.frame_ms(area))
            report[f"{name}_note"] = note()
            yield
    space.shading.show_xray, space.shading.xray_alpha = True, 0.5
    view_shots.shot(out_dir, "software_xray")
    report["xray_note"] = note()
    print(f"SOFTWARE {json.dumps(report)}", flush=True)
    yield


view_shots.walk_steps(steps(), "SOFTWARE")
