# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in a Blender window (xvfb) by tests/test_viewport.py: how often the
preview computes its AO. Blender redraws a view once per anti-aliasing
sample after each change (8 in Solid), each with the same depth; the
preview computed the AO for every one. With the demo scene through its
camera in Solid shading and the preview on: the AO computations (AOPipeline.ambient_occlusion
calls) over redraws of an unchanged view, for one with the kept AO
dropped (and whether its pixels are the reusing redraw's), after an
object moved, and after the Radius changed. Prints 'REUSE {json}' and 'REUSE: DONE'.

  blender --factory-startup --addons hbao --python viewport_reuse.py -- OUT_DIR
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
pipeline = sys.modules["hbao.viewport.pipeline"]
computed = []
ambient_occlusion = pipeline.AOPipeline.ambient_occlusion


def counted(self, *args, **kwargs):
    computed.append(1)
    return ambient_occlusion(self, *args, **kwargs)


pipeline.AOPipeline.ambient_occlusion = counted


def steps():
    area, _space = view_shots.demo_in_solid(show_overlays=False)
    view_shots.preview_on(area)
    yield
    report = {}
    first = view_shots.shot(out_dir, "reuse_first")
    yield
    report["first"] = len(computed)
    computed.clear()
    again = [view_shots.shot(out_dir, f"reuse_{k}") for k in range(3)]
    report["unchanged"] = len(computed)
    yield
    # the same frame computed afresh: the reused AO gave the same pixels
    for kept in sys.modules["hbao.viewport.draw"]._pipelines.values():
        kept._kept = None
    computed.clear()
    fresh = view_shots.shot(out_dir, "reuse_fresh")
    report["fresh"] = len(computed)
    report["same_pixels"] = bool((fresh == again[-1]).all())
    report["first_differs"] = float(abs(first - fresh).max())
    yield
    computed.clear()
    moved = next(o for o in bpy.context.scene.objects if o.type == "MESH")
    moved.location.x += 0.3
    yield
    view_shots.shot(out_dir, "reuse_moved")
    report["moved"] = len(computed)
    yield
    computed.clear()
    settings = sys.modules["hbao.viewport.view_entries"].find(area.id_data, area)
    settings.radius *= 1.5
    yield
    view_shots.shot(out_dir, "reuse_radius")
    report["radius"] = len(computed)
    print(f"REUSE {json.dumps(report)}", flush=True)
    yield


view_shots.walk_steps(steps(), "REUSE")
