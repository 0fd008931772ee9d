# SPDX-License-Identifier: GPL-2.0-or-later
"""Renders the Blender 5 multi-part EXR fixtures of tests/fixtures/.

    /root/.cache/hbao/bpy/bpy-5.0/bin/python scripts/render_blender5_multipart.py \\
        [--out tests/fixtures]

Runs in a Python that has Blender 5's `bpy` module (PyPI's bpy 5.0.x); it
refuses an older Blender, whose EXRs would not be multi-part. Blender 5 writes
multilayer EXRs as one part per pass by default, which is what these fixtures
are for. One render per colour depth; each is saved twice from the same Render
Result, so both files hold the very same pixels:

- NAME.exr: Blender 5's default multi-part layout;
- NAME_interleaved.exr: image_settings.use_exr_interleave = True, the old
  single-part layout (only written for blender5_cycles_multipart);

each with its NAME.camera.json, the camera as `hbao --camera` reads it.
"""
import argparse
import json
import math
import sys
from pathlib import Path

import bpy
from mathutils import Vector

REPO = Path(__file__).resolve().parents[1]
RESOLUTION = (48, 32)
# Few samples keep the render at a second; Depth and Normal do not need more.
SAMPLES = 2
# (file name, colour depth, codec, also write the interleaved twin)
FIXTURES = (
    ("blender5_cycles_multipart", "32", "ZIP", True),
    ("blender5_half_piz_multipart", "16", "PIZ", False),
    # B44 leaves the float Depth and Normal parts as they are: every chunk of
    # theirs is stored uncompressed, which OpenEXRCore 3.1 misread.
    ("blender5_half_b44_multipart", "16", "B44", False),
)


def camera_from_blender(scene):
    """The add-on's reading of the camera (the add-on's bpy-free camera
    module), so the JSON matches what the add-on uses."""
    sys.path.insert(0, str(REPO / "addon"))
    from hbao import camera
    return camera.camera_from_blender(scene)


def build_scene():
    """A floor and a cube on it, seen from the front and above: the cube's
    foot gives the AO something to darken."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    for obj in list(scene.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    bpy.ops.mesh.primitive_plane_add(size=8.0, location=(0.0, 0.0, 0.0))
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.0, 0.0, 0.5),
                                    rotation=(0.0, 0.0, math.radians(25.0)))
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    camera.location = (3.0, -4.0, 2.5)
    direction = Vector((0.0, 0.0, 0.4)) - camera.location
    camera.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
    scene.camera = camera
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", type="SUN"))
    scene.collection.objects.link(sun)
    sun.rotation_euler = (math.radians(40.0), 0.0, math.radians(30.0))

    render = scene.render
    render.engine = "CYCLES"
    render.resolution_x, render.resolution_y = RESOLUTION
    render.resolution_percentage = 100
    scene.cycles.device = "CPU"
    scene.cycles.samples = SAMPLES
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.seed = 0
    # Stamped dates and times would make every re-render of a fixture differ.
    render.use_stamp_date = render.use_stamp_time = render.use_stamp_render_time = False
    view_layer = scene.view_layers[0]
    view_layer.use_pass_combined = True
    view_layer.use_pass_z = True
    view_layer.use_pass_normal = True
    return scene


def save(scene, path, color_depth, codec, interleave):
    settings = scene.render.image_settings
    # Blender 5 keeps multilayer EXR under its own media type.
    settings.media_type = "MULTI_LAYER_IMAGE"
    settings.file_format = "OPEN_EXR_MULTILAYER"
    settings.color_depth = color_depth
    settings.exr_codec = codec
    settings.use_exr_interleave = interleave
    bpy.data.images["Render Result"].save_render(str(path), scene=scene)
    if not path.is_file():
        raise RuntimeError(f"Blender wrote no {path}")
    print(f"wrote {path}")


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=REPO / "tests" / "fixtures")
    arguments = parser.parse_args(argv)
    if bpy.app.version < (5, 0, 0):
        sys.exit(f"needs Blender 5.0 or later (multi-part EXRs), this is "
                 f"{bpy.app.version_string}")
    scene = build_scene()
    bpy.ops.render.render(write_still=False)
    saves = []
    for name, color_depth, codec, with_twin in FIXTURES:
        saves.append((name, color_depth, codec, False))
        if with_twin:
            saves.append((f"{name}_interleaved", color_depth, codec, True))
    for name, color_depth, codec, interleave in saves:
        save(scene, arguments.out / f"{name}.exr", color_depth, codec, interleave)
        with open(arguments.out / f"{name}.camera.json", "w", encoding="utf-8") as stream:
            json.dump(camera_from_blender(scene), stream, indent=2)
            stream.write("\n")


if __name__ == "__main__":
    main(sys.argv[1:])
