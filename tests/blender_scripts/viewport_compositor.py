# SPDX-License-Identifier: GPL-2.0-or-later
"""Run by tests/test_faults.py in bpy 5.3 (whose gpu module draws headless,
on llvmpipe, after gpu.init()): the 3D view with the Viewport Compositor on
(shading Material Preview, use_compositor ALWAYS, and CAMERA through the
camera), the compositor's output fed in turn by the Render Layers' Image
(the control), the HBAO node's Image and its AO. The Viewport Compositor
renders no other scene, so the helper's pass reads 0 there. Prints VIEWPORT
COMPOSITOR {json}: per mode, the largest |HBAO Image - control| and the AO's
least and greatest value, and the control's mean (to show it is not black).

  python bpy_blender.py --addons hbao --python viewport_compositor.py
"""
import json
import os
import sys

import bpy
import gpu
import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))
import blender_scenes  # noqa: E402

if bpy.app.background and hasattr(gpu, "init"):
    gpu.init()

WIDTH, HEIGHT = 96, 64
scene = blender_scenes.build_corner_scene(bpy.context.scene, (WIDTH, HEIGHT), "CYCLES", 4)
compositor = blender_scenes.Compositor(scene)
layers = compositor.render_layers()
hbao = compositor.node("CompositorNodeHBAO")
for name in ("Image", "Depth", "Normal"):
    compositor.link(layers.outputs[name], hbao.inputs[name])
output = compositor.composite(hbao.outputs["Image"])
sys.modules["hbao"].sync(scene)
bpy.ops.render.render()  # a render first: the pass then holds AO, which the viewport never gets

window = bpy.context.window_manager.windows[0]
area = next(area for area in window.screen.areas if area.type == "VIEW_3D")
space = area.spaces.active
region = next(region for region in area.regions if region.type == "WINDOW")
# The Viewport Compositor runs in Material Preview and Rendered shading only.
space.shading.type = "MATERIAL"
space.overlay.show_overlays = False
depsgraph = bpy.context.evaluated_depsgraph_get()
view_matrix = scene.camera.matrix_world.inverted()
projection = scene.camera.calc_matrix_camera(depsgraph, x=WIDTH, y=HEIGHT)
offscreen = gpu.types.GPUOffScreen(WIDTH, HEIGHT, format="RGBA16F")


def feed_output(socket):
    for link in list(output.inputs[0].links):
        compositor.tree.links.remove(link)
    compositor.tree.links.new(socket, output.inputs[0])


def draw(mode):
    """The view's RGB with use_compositor `mode`. draw_view3d does not
    evaluate the depsgraph: an edit reaches the compositor only after it."""
    space.region_3d.view_perspective = "CAMERA" if mode == "CAMERA" else "PERSP"
    space.shading.use_compositor = mode
    bpy.context.evaluated_depsgraph_get()
    with bpy.context.temp_override(window=window, area=area, region=region):
        for _ in range(2):
            offscreen.draw_view3d(scene, bpy.context.view_layer, space, region, view_matrix,
                                  projection, do_color_management=False)
    pixels = offscreen.texture_color.read()
    pixels.dimensions = WIDTH * HEIGHT * 4
    return np.array(pixels[:], np.float32).reshape(HEIGHT, WIDTH, 4)[..., :3]


drawn = {}
for name, socket in (("control", layers.outputs["Image"]), ("image", hbao.outputs["Image"]),
                     ("ao", hbao.outputs["AO"])):
    feed_output(socket)
    bpy.context.evaluated_depsgraph_get()
    for mode in ("ALWAYS", "CAMERA"):
        drawn[name, mode] = draw(mode)
offscreen.free()
print("VIEWPORT COMPOSITOR", json.dumps({mode: {
    "control_mean": float(drawn["control", mode].mean()),
    "image_difference": float(np.abs(drawn["image", mode] - drawn["control", mode]).max()),
    "ao_range": [float(drawn["ao", mode].min()), float(drawn["ao", mode].max())],
} for mode in ("ALWAYS", "CAMERA")}), flush=True)
