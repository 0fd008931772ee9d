# SPDX-License-Identifier: GPL-2.0-or-later
"""Renders the demo scene with the HBAO compositor node, headless, and writes
to the folder given after `--` (default out/demo):

  with_ao.png       the final image (Image x AO)
  ao.png            the node's AO
  without_ao.png    the render without AO
  side_by_side.png  without AO | AO | with AO

  blender -b --factory-startup --addons hbao --python scripts/demo_render.py -- out/demo
"""
import os
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


def build_tree(scene, out_dir):
    scene.use_nodes = True
    tree = scene.node_tree
    tree.nodes.clear()
    layers = tree.nodes.new("CompositorNodeRLayers")
    layers.location = (-500, 0)
    hbao = tree.nodes.new("CompositorNodeHBAO")
    hbao.location = (-100, 0)
    hbao.inputs["Radius"].default_value = DEMO_RADIUS
    hbao.inputs["Strength"].default_value = DEMO_STRENGTH
    composite = tree.nodes.new("CompositorNodeComposite")
    composite.location = (300, 100)
    tree.links.new(layers.outputs["Image"], hbao.inputs["Image"])
    tree.links.new(layers.outputs["Depth"], hbao.inputs["Depth"])
    tree.links.new(layers.outputs["Normal"], hbao.inputs["Normal"])
    tree.links.new(hbao.outputs["Image"], composite.inputs["Image"])

    files = tree.nodes.new("CompositorNodeOutputFile")
    files.location = (300, -200)
    files.base_path = out_dir + os.sep
    files.format.file_format = "PNG"
    files.format.color_mode = "RGB"
    files.file_slots.clear()
    for name, socket in (("without_ao_", layers.outputs["Image"]),
                         ("ao_", hbao.outputs["AO"]),
                         ("with_ao_", hbao.outputs["Image"])):
        files.file_slots.new(name)
        tree.links.new(socket, files.inputs[name])
    return files


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
    files = build_tree(scene, out_dir)
    scene.render.filepath = os.path.join(out_dir, "render")
    scene.render.image_settings.file_format = "PNG"

    start = time.perf_counter()
    bpy.ops.render.render(write_still=False)
    print(f"demo: rendered in {time.perf_counter() - start:.1f} s")

    frame = scene.frame_current
    panels = []
    for slot in files.file_slots:
        written = os.path.join(out_dir, f"{slot.path}{frame:04d}.png")
        final = os.path.join(out_dir, slot.path.rstrip("_") + ".png")
        os.replace(written, final)
        panels.append(load_pixels(final))
    side_by_side = np.concatenate(panels, axis=1)
    save_pixels(side_by_side, os.path.join(out_dir, "side_by_side.png"))
    for name in ("without_ao", "ao", "with_ao", "side_by_side"):
        print(f"demo: wrote {os.path.join(out_dir, name + '.png')}")


main()
