# SPDX-License-Identifier: GPL-2.0-or-later
"""Renders the demo scene with the HBAO compositor node, headless, and writes
to the folder given after `--` (default out/demo):

  with_ao.png       the final image (Image x AO)
  ao.png            the node's AO
  without_ao.png    the render without AO
  side_by_side.png  without AO | AO | with AO

  blender -b --factory-startup --addons hbao --python scripts/demo_render.py -- out/demo
"""
import glob
import os
import shutil
import sys
import time

import bpy
import numpy as np

SCRIPTS_DIR = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, SCRIPTS_DIR)
import blender_scenes  # noqa: E402

# AO settings that suit the demo scene (metres): contact shadows a hand wide.
DEMO_RADIUS = 0.6
DEMO_STRENGTH = 1.5


def parse_out_dir():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    out = argv[0] if argv else os.path.join(os.path.dirname(SCRIPTS_DIR), "out", "demo")
    os.makedirs(out, exist_ok=True)
    return os.path.abspath(out)


# The demo's panels, left to right: (file name, what feeds it).
PANELS = ("without_ao", "ao", "with_ao")


def build_tree(scene, out_dir):
    """Render Layers -> HBAO -> the final image, and one PNG File Output per
    panel, each into a folder of its own (Blender versions name the files
    differently; the folder finds it)."""
    compositor = blender_scenes.Compositor(scene)
    layers = compositor.render_layers(location=(-500, 0))
    hbao = compositor.node("CompositorNodeHBAO", (-100, 0))
    hbao.inputs["Radius"].default_value = DEMO_RADIUS
    hbao.inputs["Strength"].default_value = DEMO_STRENGTH
    for name in ("Image", "Depth", "Normal"):
        compositor.link(layers.outputs[name], hbao.inputs[name])
    compositor.composite(hbao.outputs["Image"], (300, 100))
    sources = {"without_ao": layers.outputs["Image"], "ao": hbao.outputs["AO"],
               "with_ao": hbao.outputs["Image"]}
    folders = {}
    for index, name in enumerate(PANELS):
        folders[name] = os.path.join(out_dir, f".{name}")
        shutil.rmtree(folders[name], ignore_errors=True)
        files = compositor.file_output(folders[name], name, (300, -200 * (index + 1)),
                                       file_format="PNG")
        files.node.format.color_mode = "RGB"
        files.add("Image", sources[name])
    return folders


def load_pixels(path):
    image = bpy.data.images.load(path, check_existing=False)
    width, height = image.size
    pixels = np.empty(width * height * 4, np.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    return pixels.reshape(height, width, 4)


def save_pixels(pixels, path):
    height, width = pixels.shape[:2]
    image = bpy.data.images.new("hbao_demo_output", width, height, alpha=False)
    image.pixels.foreach_set(pixels.reshape(-1))
    image.filepath_raw = path
    image.file_format = "PNG"
    image.save()
    bpy.data.images.remove(image)


def main():
    out_dir = parse_out_dir()
    scene = blender_scenes.build_demo_scene(bpy.context.scene)
    # Standard view: the AO image shows the AO values, not a film curve of them.
    scene.view_settings.view_transform = "Standard"
    scene.render.use_file_extension = True
    folders = build_tree(scene, out_dir)
    scene.render.filepath = os.path.join(out_dir, "render")
    blender_scenes.compat.set_image_format(scene.render.image_settings, "PNG")

    start = time.perf_counter()
    bpy.ops.render.render(write_still=False)
    print(f"demo: rendered in {time.perf_counter() - start:.1f} s")

    panels = []
    for name in PANELS:
        written = glob.glob(os.path.join(folders[name], "**", "*.png"), recursive=True)
        if len(written) != 1:
            sys.exit(f"demo: expected one PNG in {folders[name]}, found {written}")
        final = os.path.join(out_dir, name + ".png")
        os.replace(written[0], final)
        shutil.rmtree(folders[name])
        panels.append(load_pixels(final))
    side_by_side = np.concatenate(panels, axis=1)
    save_pixels(side_by_side, os.path.join(out_dir, "side_by_side.png"))
    for name in ("without_ao", "ao", "with_ao", "side_by_side"):
        print(f"demo: wrote {os.path.join(out_dir, name + '.png')}")


main()
