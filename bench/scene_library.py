# SPDX-License-Identifier: GPL-2.0-or-later
"""The benchmark's four scenes, built from scratch inside Blender.

Importable inside Blender only. Every builder empties the current scene's
objects, builds geometry from code or from an input file named by the caller
(the bunny as a JSON dump of the npm package, the robot arm from
Debian's assimp-testmodels), places the camera and returns a SceneSpec. Units are metres.

Scenes (each of a different character, for screen-space AO):
  interior  a room full of creases: shelves, stairs, crates, pillars, a table
  bunny     the Stanford bunny (scanned, smooth-shaded) standing on a floor
  mechanical  a robot arm (STL from assimp-testmodels): struts, joints, thin parts
  terrain   a ridged-noise height field through a tilted orthographic camera
"""
import math
from dataclasses import dataclass

import os
import sys

import bpy
import mathutils
from mathutils import Vector

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "scripts"))
import scene_parts  # noqa: E402  (scripts/: the parts every scene is built from)

# Debian's assimp-testmodels: a robot arm (joints, struts, a clamp), binary
# STL, which Blender 3.4 imports natively.
MECHANICAL_MODEL_PATH = "/usr/share/assimp/models/STL/3DSMaxExport.STL"

# The mechanical model is scaled so that its largest side is this long, the
# bunny so that it is this tall: radii below are chosen against these sizes.
MECHANICAL_SIZE = 2.0
BUNNY_HEIGHT = 1.0

# Terrain: a square of TERRAIN_SIZE metres, TERRAIN_CELLS quads a side,
# heights up to about TERRAIN_HEIGHT metres.
TERRAIN_SIZE = 20.0
TERRAIN_CELLS = 240
TERRAIN_HEIGHT = 5.0


@dataclass
class SceneSpec:
    """What the renderer needs to know about a built scene."""
    name: str
    #: AO radius in metres: HBAO's radius and Cycles/EEVEE's AO distance.
    radius: float
    description: str


def clear_objects():
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    for mesh in list(bpy.data.meshes):
        if mesh.users == 0:
            bpy.data.meshes.remove(mesh)


def _grey_material():
    material = bpy.data.materials.get("BenchGrey") or bpy.data.materials.new("BenchGrey")
    material.diffuse_color = (0.7, 0.7, 0.7, 1.0)
    return material


def _link(obj):
    return scene_parts.link(obj, bpy.context.scene.collection, _grey_material())


def add_box(name, centre, size, rotation_z_degrees=0.0):
    """An axis-aligned (optionally turned about z) box with flat shading."""
    return scene_parts.box(name, centre, size, bpy.context.scene.collection, _grey_material(),
                           rotation=(0.0, 0.0, math.radians(rotation_z_degrees)))


def add_cylinder(name, centre, radius, height, segments=24):
    return scene_parts.cylinder(name, centre, radius, height, bpy.context.scene.collection,
                                _grey_material(), segments)


def add_camera(location, target, lens=35.0, ortho_scale=None):
    scene = bpy.context.scene
    return scene_parts.camera(scene, scene.collection, location, target, lens=lens,
                              name="BenchCamera", ortho_scale=ortho_scale, clip=(0.05, 500.0))


# --- interior ---------------------------------------------------------------

def build_interior(_inputs):
    clear_objects()
    # Room 7 x 6 x 3 m, walls as thick boxes so every surface is closed.
    add_box("Floor", (0, 0, -0.1), (7.4, 6.4, 0.2))
    add_box("Ceiling", (0, 0, 3.1), (7.4, 6.4, 0.2))
    add_box("WallBack", (0, 3.1, 1.5), (7.4, 0.2, 3.2))
    add_box("WallLeft", (-3.6, 0, 1.5), (0.2, 6.4, 3.2))
    add_box("WallRight", (3.6, 0, 1.5), (0.2, 6.4, 3.2))
    add_box("WallFront", (0, -3.1, 1.5), (7.4, 0.2, 3.2))
    # Skirting boards and a ceiling beam: long thin creases.
    for x in (-3.45, 3.45):
        add_box(f"Skirting{x}", (x, 0, 0.06), (0.1, 6.0, 0.12))
    add_box("SkirtingBack", (0, 2.95, 0.06), (7.0, 0.1, 0.12))
    add_box("Beam", (0, 0.5, 2.85), (7.0, 0.35, 0.3))
    # A bookshelf against the back wall: boards and books.
    for level in range(5):
        add_box(f"Shelf{level}", (-1.8, 2.75, 0.1 + 0.45 * level), (2.2, 0.4, 0.04))
    for side in (-2.9, -0.7):
        add_box(f"ShelfSide{side}", (side, 2.75, 0.95), (0.04, 0.4, 1.9))
    for level in range(4):
        for k in range(9):
            height = 0.22 + 0.12 * ((k * 7 + level * 3) % 5) / 4.0
            add_box(f"Book{level}_{k}", (-2.75 + 0.2 * k + 0.05 * level, 2.8,
                                         0.12 + 0.45 * level + height / 2.0),
                    (0.12, 0.28, height), rotation_z_degrees=(k % 3 - 1) * 4.0)
    # Stairs up the right wall.
    for step in range(10):
        add_box(f"Step{step}", (3.0, 2.6 - 0.32 * step, 0.1 + 0.2 * step),
                (1.0, 0.32, 0.2 + 0.4 * step))
    # Crates stacked near the left wall.
    crates = [((-2.9, -0.5, 0.3), 0.6, 10), ((-2.85, 0.25, 0.3), 0.6, -5),
              ((-2.9, -0.2, 0.9), 0.55, 20), ((-2.2, -1.2, 0.2), 0.4, 35)]
    for index, (centre, size, turn) in enumerate(crates):
        add_box(f"Crate{index}", centre, (size, size, size), rotation_z_degrees=turn)
    # Pillars and a table with four legs and two chairs.
    for index, (x, y) in enumerate(((-1.7, 0.3), (1.4, 1.0))):
        add_cylinder(f"Pillar{index}", (x, y, 1.5), 0.2, 3.0)
    add_box("TableTop", (0.6, -0.6, 0.74), (1.4, 0.8, 0.05))
    for index, (x, y) in enumerate(((-0.05, -0.95), (1.25, -0.95), (-0.05, -0.25), (1.25, -0.25))):
        add_box(f"TableLeg{index}", (x, y, 0.36), (0.06, 0.06, 0.72))
    for index, (x, y, turn) in enumerate(((0.2, 0.05, 10), (1.0, -1.35, 190))):
        add_box(f"ChairSeat{index}", (x, y, 0.45), (0.45, 0.45, 0.05), turn)
        back = Vector((0.0, 0.21, 0.0))
        back.rotate(mathutils.Euler((0.0, 0.0, math.radians(turn))))
        add_box(f"ChairBack{index}", (x + back.x, y + back.y, 0.72), (0.45, 0.04, 0.5), turn)
        for k, (dx, dy) in enumerate(((-0.2, -0.2), (0.2, -0.2), (-0.2, 0.2), (0.2, 0.2))):
            leg = Vector((dx, dy, 0.0))
            leg.rotate(mathutils.Euler((0.0, 0.0, math.radians(turn))))
            add_box(f"ChairLeg{index}_{k}", (x + leg.x, y + leg.y, 0.22), (0.04, 0.04, 0.44), turn)
    add_camera((1.2, -2.8, 1.7), (-0.6, 1.6, 0.8), lens=20.0)
    return SceneSpec("interior", 0.5, "room with shelves, books, stairs, crates, table and "
                                      "chairs (perspective, 20 mm lens)")


# --- bunny --------------------------------------------------------------------

def build_bunny(inputs):
    import json
    clear_objects()
    with open(inputs["bunny_json"], encoding="utf-8") as handle:
        bunny = json.load(handle)
    positions = bunny["positions"]
    min_y = min(p[1] for p in positions)
    max_y = max(p[1] for p in positions)
    scale = BUNNY_HEIGHT / (max_y - min_y)
    # The npm bunny is y-up; Blender is z-up.
    vertices = [(p[0] * scale, -p[2] * scale, (p[1] - min_y) * scale) for p in positions]
    mesh = bpy.data.meshes.new("Bunny")
    mesh.from_pydata(vertices, [], [tuple(c) for c in bunny["cells"]])
    mesh.update()
    for polygon in mesh.polygons:
        polygon.use_smooth = True
    _link(bpy.data.objects.new("Bunny", mesh))
    add_box("Floor", (0, 0, -0.05), (6.0, 6.0, 0.1))
    add_box("BackWall", (0, 1.2, 0.8), (6.0, 0.1, 1.7))
    add_camera((1.1, -1.9, 1.0), (0.0, 0.1, 0.42), lens=40.0)
    return SceneSpec("bunny", 0.25, "Stanford bunny (npm `bunny`, 1839 vertices, smooth "
                                    "shaded) on a floor before a wall (perspective, 40 mm)")


# --- mechanical -----------------------------------------------------------------

def build_mechanical(inputs):
    clear_objects()
    path = inputs.get("mechanical_model") or MECHANICAL_MODEL_PATH
    before = set(bpy.data.objects)
    bpy.ops.import_mesh.stl(filepath=path)
    meshes = [obj for obj in bpy.data.objects if obj not in before and obj.type == "MESH"]
    if not meshes:
        raise RuntimeError(f"no mesh imported from {path}")
    bpy.context.view_layer.update()
    corners = [obj.matrix_world @ Vector(c) for obj in meshes for c in obj.bound_box]
    low = Vector(tuple(min(c[k] for c in corners) for k in range(3)))
    high = Vector(tuple(max(c[k] for c in corners) for k in range(3)))
    scale = MECHANICAL_SIZE / max(high - low)
    centre = (low + high) / 2.0
    for obj in meshes:
        # Bake the placement into the mesh: the model stands on the floor, centred.
        obj.data.transform(mathutils.Matrix.Translation(-centre))
        obj.data.transform(mathutils.Matrix.Scale(scale, 4))
        obj.location = (0.0, 0.0, (centre.z - low.z) * scale)
        for polygon in obj.data.polygons:
            polygon.use_smooth = False
        obj.data.materials.clear()
        obj.data.materials.append(_grey_material())
    add_box("Floor", (0, 0, -0.05), (8.0, 8.0, 0.1))
    add_box("BackWall", (0, 1.6, 1.0), (8.0, 0.1, 2.1))
    height = (high.z - low.z) * scale
    add_camera((1.9, -2.6, 0.5 + 0.9 * height), (0.0, 0.0, 0.5 * height), lens=50.0)
    return SceneSpec("mechanical", 0.3,
                     "robot arm from assimp-testmodels (STL/3DSMaxExport.STL, 2000 "
                     "flat-shaded triangles) on a floor before a wall (perspective, 50 mm)")


# --- terrain --------------------------------------------------------------------

def terrain_height(x, y):
    """Ridged multifractal noise: sharp ridges and valleys (deterministic)."""
    point = Vector((x * 0.15, y * 0.15, 0.0))
    ridges = mathutils.noise.ridged_multi_fractal(point, 1.0, 2.1, 5, 1.0, 2.0,
                                                  noise_basis="PERLIN_ORIGINAL")
    return TERRAIN_HEIGHT * 0.45 * ridges


def build_terrain(_inputs):
    clear_objects()
    n = TERRAIN_CELLS
    step = TERRAIN_SIZE / n
    vertices = []
    for j in range(n + 1):
        for i in range(n + 1):
            x = -TERRAIN_SIZE / 2.0 + i * step
            y = -TERRAIN_SIZE / 2.0 + j * step
            vertices.append((x, y, terrain_height(x, y)))
    faces = [(j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1,
              (j + 1) * (n + 1) + i) for j in range(n) for i in range(n)]
    mesh = bpy.data.meshes.new("Terrain")
    mesh.from_pydata(vertices, [], faces)
    mesh.update()
    _link(bpy.data.objects.new("Terrain", mesh))
    # Looking down 40 degrees off vertical, orthographic: the image shows only terrain.
    add_camera((0.0, -12.0, 14.0), (0.0, 0.0, 0.0), ortho_scale=12.0)
    return SceneSpec("terrain", 1.5, f"ridged-noise height field, {n}x{n} quads over "
                                     f"{TERRAIN_SIZE:.0f} m (orthographic, scale 12)")


BUILDERS = {
    "interior": build_interior,
    "bunny": build_bunny,
    "mechanical": build_mechanical,
    "terrain": build_terrain,
}
SCENE_NAMES = tuple(BUILDERS)


def build(name, inputs):
    """Build scene `name` in the current Blender scene; returns its SceneSpec."""
    return BUILDERS[name](inputs)
