# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in a real Blender window (xvfb) by tests/test_ui.py: re-compositing
after a node's settings changed, with the compositor open in the window as an
artist has it.

1. F12 (the render job's thread) of the corner scene with its HBAO node;
2. the node's Radius quadrupled: once the add-on's timer has brought the AO
   up to date, the composited image;
3. F12 again with that Radius: the image an artist would otherwise have had
   to render for;
4. the Normal input unlinked (the AO now needs other passes): after a wait,
   the composited image and the node's hint.

Each image is the Render Result's composite, saved as a float EXR and read
back; they are printed as 'IMAGE <name> <mean> <sha256 of the floats>' and the
hint as 'HINT <json>', so the test compares them.

  blender --addons hbao --python ui_recomposite.py -- <out dir>
"""
import hashlib
import json
import os
import sys
import time

import bpy

out_dir = sys.argv[sys.argv.index("--") + 1]
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import f12_job  # noqa: E402
import timer_guard  # noqa: E402

sys.path.insert(0, os.path.join(f12_job.REPO, "addon"))
from hbao import exr_passes  # noqa: E402  (needs the path above)

# The add-on's timer polls every 0.25 s; the compositor job then runs.
SETTLE_S = 3.0

scene, node = f12_job.corner_scene_with_node(out_dir)
tree = node.id_data
job = f12_job.F12Job("RECOMPOSITE")
state = {"phase": "start", "since": time.monotonic(), "images": 0}


def print_image(name):
    image = next(i for i in bpy.data.images if i.type == "RENDER_RESULT")
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR"
    settings.color_depth = "32"
    state["images"] += 1
    path = os.path.join(out_dir, f"composite_{state['images']}.exr")
    image.save_render(path, scene=scene)
    names = [channel for channel in exr_passes.channel_names(path) if channel in "RGB"]
    channels = exr_passes.read_channels(path, names)
    digest = hashlib.sha256(b"".join(channels[c].tobytes() for c in names)).hexdigest()
    mean = sum(float(channels[c].mean()) for c in names) / len(names)
    print(f"IMAGE {name} {mean:.6f} {digest}", flush=True)


def render(next_phase):
    job.start()
    state.update(phase="rendering", after=next_phase, since=time.monotonic())


def tick():
    now = time.monotonic()
    phase = state["phase"]
    if phase == "start":
        f12_job.show_compositor()
        render("rendered")
    elif phase == "rendering":
        if job.finished():
            state.update(phase=state["after"], since=now)
    elif phase == "rendered" and now - state["since"] > SETTLE_S:
        print_image("first_render")
        node.inputs["Radius"].default_value *= 4.0
        state.update(phase="changed", since=now)
    elif phase == "changed" and now - state["since"] > SETTLE_S:
        print_image("recomposited")
        print(f"HINT {json.dumps(node.hint)}", flush=True)
        render("rerendered")
    elif phase == "rerendered" and now - state["since"] > SETTLE_S:
        print_image("rendered_with_new_radius")
        tree.links.remove(node.inputs["Normal"].links[0])
        state.update(phase="unlinked", since=now)
    elif phase == "unlinked" and now - state["since"] > SETTLE_S:
        print_image("normal_unlinked")
        print(f"HINT {json.dumps(node.hint)}", flush=True)
        print("RECOMPOSITE: DONE", flush=True)
        timer_guard.quit_blender()
        return None
    return 0.1


timer_guard.guarded_timer(tick, 1.0)
