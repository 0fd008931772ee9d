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

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))), "scripts"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import view_shots  # noqa: E402

out_dir = sys.argv[sys.argv.index("--") + 1]


def steps():
    area, space = view_shots.demo_in_solid(show_overlays=False)
    for alpha in (1.0, 0.5):
        space.shading.show_xray, space.shading.xray_alpha = True, alpha
        off = view_shots.shot(out_dir, f"xray_{int(alpha * 100)}_off")
        view_shots.preview_on(area)
        on = view_shots.shot(out_dir, f"xray_{int(alpha * 100)}_on")
        view_shots.toggle_preview()
        why = sys.modules["hbao.viewport.draw"].not_drawn(space)
        darkened = float((on < off - 2.0 / 255.0).mean())
        print(f"XRAY {alpha} {json.dumps({'darkened': darkened, 'not_drawn': why})}",
              flush=True)
    yield


view_shots.walk_steps(steps(), "XRAY")
