# SPDX-License-Identifier: GPL-2.0-or-later
"""Renders a scene of blender_scenes.py and writes its passes as a multilayer EXR.

    blender -b --factory-startup --python scripts/render_passes.py -- \\
        --scene demo --out out/demo --width 640 --height 360 \\
        [--engine CYCLES|BLENDER_EEVEE] [--samples N] [--half] [--codec ZIP] \\
        [--ortho] [--ao-distance D] [--no-depth] [--production-passes] [--png] [--force]

Writes OUT.exr (every pass of the Render Result: Depth, Normal, AO when asked,
Combined) and OUT.camera.json (the camera as the `hbao` CLI reads it). An
existing OUT.exr or OUT.camera.json is left alone unless --force is given.
Bad arguments print an error and exit with status 2; a failed render or write
exits with status 1.
"""
import argparse
import json
import os
import sys
from pathlib import Path

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender_scenes  # noqa: E402  (needs the path above)
from blender_arguments import (  # noqa: E402
    ArgumentError, ArgumentParser, end_blender, script_arguments)

EXIT_BAD_ARGUMENTS = 2
EXIT_FAILED = 1

# Blender's image_settings.color_depth values for OpenEXR.
HALF_FLOAT_DEPTH = "16"
FULL_FLOAT_DEPTH = "32"


def exr_codecs():
    settings = bpy.context.scene.render.image_settings
    return [item.identifier for item in settings.bl_rna.properties["exr_codec"].enum_items]


def positive_int(text):
    value = int(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be a positive integer, got {text}")
    return value


def positive_float(text):
    value = float(text)
    if not value > 0.0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"must be a positive number, got {text}")
    return value


def parse_arguments(argv):
    parser = ArgumentParser(
        prog="render_passes.py",
        description="Render a test scene and write its passes as a multilayer EXR.")
    parser.add_argument("--scene", required=True, choices=sorted(blender_scenes.SCENE_BUILDERS))
    parser.add_argument("--out", required=True,
                        help="output path without extension: writes OUT.exr and OUT.camera.json")
    parser.add_argument("--width", type=positive_int, default=None)
    parser.add_argument("--height", type=positive_int, default=None)
    parser.add_argument("--engine", choices=blender_scenes.ENGINES, default="CYCLES")
    parser.add_argument("--samples", type=positive_int, default=blender_scenes.DEFAULT_SAMPLES)
    parser.add_argument("--half", action="store_true", help="16-bit half float (default 32-bit)")
    parser.add_argument("--codec", default="ZIP", choices=exr_codecs())
    parser.add_argument("--ortho", action="store_true", help="orthographic camera")
    parser.add_argument("--ao-distance", type=positive_float, default=None,
                        help="also write an AO pass with rays this long (metres)")
    parser.add_argument("--no-depth", action="store_true", help="leave the Depth pass out")
    parser.add_argument("--production-passes", action="store_true",
                        help="a compositing artist's usual passes as well (light passes, "
                        "mist, Cryptomatte, ...)")
    parser.add_argument("--png", action="store_true",
                        help="also write OUT.png, the Combined pass as the viewer sees it")
    parser.add_argument("--force", action="store_true", help="overwrite existing outputs")
    arguments = parser.parse_args(argv)
    if (arguments.width is None) != (arguments.height is None):
        parser.error("give both --width and --height, or neither")
    return arguments


def output_paths(out, force, png):
    """OUT.exr, OUT.camera.json and OUT.png (None unless asked for)."""
    base = Path(out)
    if base.suffix.lower() == ".exr":
        base = base.with_suffix("")
    exr_path = base.with_name(base.name + ".exr")
    camera_path = base.with_name(base.name + ".camera.json")
    png_path = base.with_name(base.name + ".png") if png else None
    if not base.parent.is_dir():
        raise ArgumentError(f"--out: folder {base.parent} does not exist")
    if not force:
        for path in (exr_path, camera_path, png_path):
            if path is not None and path.exists():
                raise ArgumentError(f"--out: {path} exists; pass --force to overwrite it")
    return exr_path, camera_path, png_path


def build_scene(arguments):
    builder = blender_scenes.SCENE_BUILDERS[arguments.scene]
    options = {"engine": arguments.engine, "samples": arguments.samples}
    if arguments.width is not None:
        options["resolution"] = (arguments.width, arguments.height)
    scene = builder(bpy.context.scene, **options)
    if arguments.ortho:
        blender_scenes.make_orthographic(scene)
    for view_layer in scene.view_layers:
        blender_scenes.enable_passes(view_layer, depth=not arguments.no_depth, normal=True,
                                     ao=arguments.ao_distance is not None)
        if arguments.production_passes:
            blender_scenes.enable_production_passes(view_layer)
    if arguments.ao_distance is not None:
        blender_scenes.configure_ao_reference(scene, arguments.ao_distance)
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR_MULTILAYER"
    settings.color_depth = HALF_FLOAT_DEPTH if arguments.half else FULL_FLOAT_DEPTH
    settings.exr_codec = arguments.codec
    # Stamped dates and times would make every re-render of a fixture differ.
    scene.render.use_stamp_date = False
    scene.render.use_stamp_time = False
    scene.render.use_stamp_render_time = False
    return scene


def save_png(result, scene, png_path):
    settings = scene.render.image_settings
    saved = settings.file_format, settings.color_depth
    settings.file_format = "PNG"
    settings.color_depth = "8"
    try:
        result.save_render(str(png_path), scene=scene)
    finally:
        settings.file_format, settings.color_depth = saved


def render_and_write(scene, exr_path, camera_path, png_path=None):
    bpy.ops.render.render(write_still=False, scene=scene.name)
    result = bpy.data.images["Render Result"]
    result.save_render(str(exr_path), scene=scene)
    if not exr_path.is_file():
        raise RuntimeError(f"Blender wrote no {exr_path}")
    if png_path is not None:
        save_png(result, scene, png_path)
    with open(camera_path, "w", encoding="utf-8") as stream:
        json.dump(blender_scenes.camera_description(scene), stream, indent=2)
        stream.write("\n")


def main():
    try:
        arguments = parse_arguments(script_arguments())
        exr_path, camera_path, png_path = output_paths(arguments.out, arguments.force,
                                                       arguments.png)
    except ArgumentError as error:
        print(f"render_passes.py: error: {error}", file=sys.stderr)
        return EXIT_BAD_ARGUMENTS
    except SystemExit as done:  # --help
        return done.code or 0
    try:
        scene = build_scene(arguments)
        render_and_write(scene, exr_path, camera_path, png_path)
    except (RuntimeError, ValueError, OSError) as error:
        print(f"render_passes.py: error: {error}", file=sys.stderr)
        return EXIT_FAILED
    print(f"render_passes.py: wrote {exr_path} and {camera_path}")
    return 0


if __name__ == "__main__":
    end_blender(main())
