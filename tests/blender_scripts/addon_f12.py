# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in a real Blender window (xvfb) by tests/test_addon.py: an F12-style
render in the render job thread (render.render('INVOKE_DEFAULT') from a
timer), waits for render_complete, saves the Render Result and the node's AO
(File Output), then quits.

  blender --addons hbao --python addon_f12.py -- <out dir> [stereo]

With "stereo", Stereo 3D is on: the Render Result and the node's AO are
saved per view (_L, _R), with each eye's camera_0001_<view>.json.
"""
import os
import sys

import bpy

arguments = sys.argv[sys.argv.index("--") + 1:]
out_dir = arguments[0]
stereo = arguments[1:] == ["stereo"]
REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))
import blender_scenes  # noqa: E402
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import timer_guard  # noqa: E402

# Wait for the render at most this long (Cycles at 96x64 takes a second).
RENDER_TIMEOUT_S = 240.0

scene = blender_scenes.build_corner_scene(bpy.context.scene, (96, 64), "CYCLES", 4)
hbao = blender_scenes.hbao_test_tree(scene, out_dir)
hbao.inputs["Radius"].default_value = 0.9
os.makedirs(out_dir, exist_ok=True)
bpy.context.view_layer.update()  # matrix_world of the new camera
cameras = {"": blender_scenes.camera_description(scene)}
if stereo:
    scene.render.use_multiview = True
    scene.render.views_format = "STEREO_3D"
    cameras.update(blender_scenes.view_camera_descriptions(scene))
for suffix, description in cameras.items():
    with open(os.path.join(out_dir, f"camera_0001{suffix}.json"), "w") as stream:
        import json
        json.dump(description, stream)

state = {"done": False, "started": None}


def on_complete(*_args):
    state["done"] = True


bpy.app.handlers.render_complete.append(on_complete)
bpy.app.handlers.render_cancel.append(on_complete)


def start_render():
    print("F12: invoking render in the job thread")
    bpy.ops.render.render("INVOKE_DEFAULT")
    return None


def wait_and_quit():
    import time
    if state["started"] is None:
        state["started"] = time.monotonic()
    if not state["done"]:
        if time.monotonic() - state["started"] > RENDER_TIMEOUT_S:
            timer_guard.give_up("F12: TIMEOUT")
        return 0.25
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR_MULTILAYER"
    settings.color_depth = "32"
    settings.exr_codec = "NONE"
    try:
        bpy.data.images["Render Result"].save_render(os.path.join(out_dir, "frame_0001.exr"),
                                                     scene=scene)
    except RuntimeError as error:  # a stereo save says so after writing every view
        print("F12: save said", error)
    print("F12: RENDERED")
    timer_guard.quit_blender()
    return None


timer_guard.guarded_timer(start_render, 1.0)
timer_guard.guarded_timer(wait_and_quit, 1.5)
