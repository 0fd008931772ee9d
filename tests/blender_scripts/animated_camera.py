# SPDX-License-Identifier: GPL-2.0-or-later
"""Builds the demo scene with a camera that turns and zooms over frames 1-3
(and a marker that switches to a second camera at frame 4), saves it as
BLEND, and writes what Blender itself says each frame's camera is (its
evaluated world matrix inverted, its lens) as JSON, for
tests/test_cli.py's check of scripts/export_cameras.py. With --no-camera,
the scene is saved without any camera instead. With --motion-blur-start,
Cycles' camera motion blur is on (a shutter of 1 frame opening at the
frame): each frame's camera is then the frame's camera object at the middle
of the shutter, half a frame on (and "at_frame" holds its matrix at the
frame itself).

    blender -b --python animated_camera.py -- BLEND EXPECTED.json [--no-camera]
        [--motion-blur-start]
"""
import json
import sys
from pathlib import Path

import bpy

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "scripts"))

import blender_scenes  # noqa: E402


def main():
    arguments = sys.argv[sys.argv.index("--") + 1:]
    blend, expected_path = arguments[:2]
    scene = bpy.context.scene
    blender_scenes.build_demo_scene(scene)
    camera = scene.camera
    if "--no-camera" in arguments:
        bpy.data.objects.remove(camera)
        bpy.ops.wm.save_as_mainfile(filepath=blend)
        return
    scene.frame_start, scene.frame_end = 1, 4
    camera.keyframe_insert("rotation_euler", frame=1)
    camera.data.keyframe_insert("lens", frame=1)
    camera.rotation_euler.z += 0.3
    camera.data.lens *= 1.5
    camera.keyframe_insert("rotation_euler", frame=3)
    camera.data.keyframe_insert("lens", frame=3)
    # a second camera, which a marker makes the scene's at frame 4
    other = camera.copy()
    other.data = camera.data.copy()
    other.animation_data_clear()
    other.data.animation_data_clear()
    other.location.x += 2.0
    scene.collection.objects.link(other)
    scene.timeline_markers.new("switch", frame=4).camera = other
    scene.timeline_markers.new("first", frame=1).camera = camera
    shutter_middle = 0.0
    if "--motion-blur-start" in arguments:
        scene.render.engine = "CYCLES"
        scene.render.use_motion_blur = True
        scene.render.motion_blur_shutter = 1.0
        settings = scene.render if hasattr(scene.render, "motion_blur_position") else scene.cycles
        settings.motion_blur_position = "START"
        shutter_middle = 0.5
    expected = {}
    for frame in range(1, 5):
        scene.frame_set(frame)
        chosen = scene.camera  # (markers switch it at the frame)
        at_frame = chosen.evaluated_get(bpy.context.evaluated_depsgraph_get()).matrix_world
        at_frame = [list(row) for row in at_frame.inverted()]
        scene.frame_set(frame, subframe=shutter_middle)
        depsgraph = bpy.context.evaluated_depsgraph_get()
        seen = chosen.evaluated_get(depsgraph)
        expected[frame] = {"world_to_camera": [list(row) for row in
                                               seen.matrix_world.inverted()],
                           "lens": seen.data.lens, "name": chosen.name, "at_frame": at_frame}
    scene.frame_set(1)
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    Path(expected_path).write_text(json.dumps(expected))


main()
