# SPDX-License-Identifier: GPL-2.0-or-later
"""Stereo 3D's eyes as Blender places them, where no render engine can be
asked: scripts/export_cameras.py writes each eye's camera for the CLI. The
add-on's engine asks Blender itself (view_cameras.camera_of_view:
RenderEngine.camera_model_matrix and camera_shift_x); tests/test_cli.py
holds the two to each other, in each convergence mode and pivot. bpy-free.

The eye at the pivot is the camera itself. The other eye (each eye, with
the pivot at the centre, by half the distance) lies the interocular
distance along the camera's x axis; Off-Axis shifts its view towards the
convergence plane (shift_x by distance / sensor width x lens /
convergence distance), Toe-in turns it about the camera's y axis to look
at the convergence point, and Parallel does neither."""
import math

import numpy as np


def _turn(angle):
    """A turn by `angle` about y, as Blender's toe-in rotation writes it."""
    cos, sin = math.cos(angle), math.sin(angle)
    return np.array([[cos, 0.0, -sin, 0.0], [0.0, 1.0, 0.0, 0.0], [sin, 0.0, cos, 0.0],
                     [0.0, 0.0, 0.0, 1.0]])


def _along_x(distance):
    moved = np.identity(4)
    moved[0, 3] = distance
    return moved


def eye(description, stereo, left):
    """The camera dict (camera.camera_from_blender's, the mono camera) of
    the left or right eye. `stereo`: the camera data's Stereoscopy settings
    as a dict (interocular_distance, convergence_distance,
    convergence_mode, pivot)."""
    pivot, mode = stereo["pivot"], stereo["convergence_mode"]
    if (pivot == "LEFT" and left) or (pivot == "RIGHT" and not left):
        return dict(description)
    distance = stereo["interocular_distance"]
    convergence = stereo["convergence_distance"]
    share = 0.5 if pivot == "CENTER" else 1.0
    signed = share if left else -share
    if mode == "TOE":
        toe_share, toe_signed = (-share, -signed) if pivot == "CENTER" else (share, signed)
        turn = _turn(math.atan(distance * 0.5 / convergence) / toe_share * toe_signed)
        if pivot == "CENTER":
            offset = turn.copy()
            offset[0, 3] = distance * toe_signed
        else:
            offset = turn @ _along_x(-distance * toe_signed) @ turn
    else:
        offset = _along_x(-distance * signed)
    to_world = np.linalg.inv(np.array(description["world_to_camera"], dtype=np.float64))
    result = dict(description)
    result["world_to_camera"] = np.linalg.inv(to_world @ offset).tolist()
    if mode == "OFFAXIS":
        result["shift_x"] = description["shift_x"] + (
            distance / description["sensor_width"] * (description["lens"] / convergence) * signed)
    return result
