# SPDX-License-Identifier: GPL-2.0-or-later
"""Run inside Blender by tests/test_cli.py: a File Output node writes the
corner scene's Depth into a multilayer EXR at half float with B44, which
Blender offers for half only and which keeps about 6 bits of each value's
difference in a 4x4 block: a depth stored with loss ("Depth.V"). A second
node writes the same Depth at half float with PIZ (lossless for half), and
the camera goes to OUT/camera.json.

  blender -b --python file_output_half_b44.py -- OUT
"""
import json
import os
import sys

import bpy

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))
import blender_scenes  # noqa: E402

out_dir = sys.argv[sys.argv.index("--") + 1]
scene = blender_scenes.build_corner_scene(bpy.context.scene, (64, 48), "CYCLES", 1)
compositor = blender_scenes.Compositor(scene)
layers = compositor.render_layers()
for codec in ("B44", "PIZ"):
    files = compositor.file_output(out_dir, f"{codec.lower()}_")
    files.node.format.color_depth = "16"
    files.node.format.exr_codec = codec
    files.add("Depth", layers.outputs["Depth"])
compositor.composite(layers.outputs["Image"])
scene.render.filepath = os.path.join(out_dir, "render")
bpy.ops.render.render(write_still=True)
with open(os.path.join(out_dir, "camera.json"), "w") as camera:
    json.dump(blender_scenes.camera_description(scene), camera)
print("FILE OUTPUT DONE", flush=True)
