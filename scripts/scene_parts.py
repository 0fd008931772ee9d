# SPDX-License-Identifier: GPL-2.0-or-later
"""The parts every scene of the project is built from (test and demo scenes
in scripts/blender_scenes.py, the benchmark's in bench/scene_library.py):
meshes made from their vertices (no bpy.ops, so no context is needed), a
camera aimed at a point, and linking an object into a collection with a
material. Importable inside Blender only."""
import math

import bpy
from mathutils import Vector


def link(obj, collection, material=None):
    """`obj` into `collection` only (out of wherever it was), with `material`
    as its one material when given."""
    for owner in list(obj.users_collection):
        owner.objects.unlink(obj)
    collection.objects.link(obj)
    if material is not None and obj.type == "MESH":
        obj.data.materials.clear()
        obj.data.materials.append(material)
    return obj


def box(name, centre, size, collection, material=None, rotation=(0.0, 0.0, 0.0)):
    """A box of `size` (x, y, z) around `centre`, turned by the Euler angles
    `rotation` (radians), flat shaded."""
    mesh = bpy.data.meshes.new(name)
    hx, hy, hz = (s / 2.0 for s in size)
    vertices = [(x, y, z) for x in (-hx, hx) for y in (-hy, hy) for z in (-hz, hz)]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    mesh.from_pydata(vertices, [], faces)
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    obj.location = centre
    obj.rotation_euler = rotation
    return link(obj, collection, material)


def cylinder(name, centre, radius, height, collection, material=None, segments=24):
    """A closed cylinder standing on z, flat shaded."""
    mesh = bpy.data.meshes.new(name)
    vertices, faces = [], []
    for k in range(segments):
        a = 2.0 * math.pi * k / segments
        vertices += [(radius * math.cos(a), radius * math.sin(a), -height / 2.0),
                     (radius * math.cos(a), radius * math.sin(a), height / 2.0)]
    for k in range(segments):
        n = (k + 1) % segments
        faces.append((2 * k, 2 * n, 2 * n + 1, 2 * k + 1))
    faces.append(tuple(range(2 * segments - 2, -1, -2)))
    faces.append(tuple(range(1, 2 * segments, 2)))
    mesh.from_pydata(vertices, [], faces)
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    obj.location = centre
    return link(obj, collection, material)


def look_at(obj, target):
    """Turns `obj` (a camera: it looks down its -Z, Y up) towards `target`."""
    direction = Vector(target) - Vector(obj.location)
    obj.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()


def camera(scene, collection, location, target, lens=35.0, name="Camera", ortho_scale=None,
           clip=None):
    """The scene's camera at `location` looking at `target`; orthographic when
    `ortho_scale` is given; `clip` (start, end) when given."""
    data = bpy.data.cameras.new(name)
    data.lens = lens
    data.sensor_fit = "AUTO"
    if clip is not None:
        data.clip_start, data.clip_end = clip
    if ortho_scale is not None:
        data.type = "ORTHO"
        data.ortho_scale = ortho_scale
    obj = bpy.data.objects.new(name, data)
    collection.objects.link(obj)
    obj.location = location
    look_at(obj, target)
    scene.camera = obj
    return obj
