# SPDX-License-Identifier: GPL-2.0-or-later
"""Run headless (`-b`, and the bpy builds) by tests/test_faults.py: the
artist's output settings, as the add-on finds them, must be as they were
after a render that hands the passes over through a file (the add-on sets
the output to multilayer EXR for that save and puts it back). The corner
scene with an HBAO node; CASE "colorspace": PNG output whose colour
management overrides the scene's, with a linear colour space other than
the default (where the version has those settings); "movie": FFmpeg
output, QuickTime with PNG frames, no audio. Prints 'SETTINGS {"before":
{...}, "after": {...}}': every plain setting of the output's image
settings, of its linear colour space, and of FFmpeg's, before and after
one render.

  blender -b --addons hbao --python output_settings_kept.py -- OUT CASE
"""
import json
import os
import sys

import bpy

arguments = sys.argv[sys.argv.index("--") + 1:]
out_dir, case = arguments[0], arguments[1]
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))), "scripts"))
import blender_scenes  # noqa: E402

PLAIN = ("BOOLEAN", "INT", "FLOAT", "ENUM", "STRING")


def plain_settings(struct):
    if struct is None:
        return {}
    return {prop.identifier: getattr(struct, prop.identifier)
            for prop in struct.bl_rna.properties
            if prop.type in PLAIN and not prop.is_readonly and not getattr(prop, "is_array", False)}


def snapshot(scene):
    settings = scene.render.image_settings
    return {"image": plain_settings(settings),
            "linear": plain_settings(getattr(settings, "linear_colorspace_settings", None)),
            "ffmpeg": plain_settings(getattr(scene.render, "ffmpeg", None))}


scene = blender_scenes.build_corner_scene(bpy.context.scene, (64, 48), "CYCLES", 1)
os.makedirs(out_dir, exist_ok=True)
blender_scenes.hbao_test_tree(scene, out_dir)
settings = scene.render.image_settings
if case == "colorspace":
    blender_scenes.compat.set_image_format(settings, "PNG")
    if hasattr(settings, "color_management"):
        settings.color_management = "OVERRIDE"
    linear = getattr(settings, "linear_colorspace_settings", None)
    if linear is not None:
        names = [item.identifier for item in linear.bl_rna.properties["name"].enum_items]
        linear.name = next(n for n in names if n != linear.name and n.startswith("Linear"))
elif case == "movie":
    if hasattr(settings, "media_type"):  # 5.0+: the formats of the media type
        settings.media_type = "VIDEO"
    settings.file_format = "FFMPEG"
    scene.render.ffmpeg.format = "QUICKTIME"
    scene.render.ffmpeg.codec = "PNG"
    scene.render.ffmpeg.audio_codec = "NONE"
else:
    raise SystemExit(f"output_settings_kept.py: unknown case {case!r}")
before = snapshot(scene)
bpy.ops.render.render(write_still=False)
print("SETTINGS " + json.dumps({"before": before, "after": snapshot(scene)}), flush=True)
