# SPDX-License-Identifier: GPL-2.0-or-later
"""A render engine written in Python, as a third-party engine add-on is (an
engine that is not Cycles): it casts one ray a pixel through the scene
(`Scene.ray_cast`) and writes Combined (the surface normal, shaded), Depth
(planar, as Cycles') and Normal (world space), in horizontal bands, each
its own begin_result() and end_result(), as a tiled engine writes them.
Perspective cameras only; slow (Python), so for small test renders."""
import bpy
import numpy as np
from mathutils import Vector

IDNAME = "HBAO_TEST_RAYCAST"
BANDS = 3
BACKGROUND_DEPTH = 1e10  # Blender's depth where nothing was hit


def _rays(scene, camera, width, height):
    """The pixel centres' x (columns) and y (rows, from the bottom) on the
    camera's view plane, and that plane's z: each pixel's ray in camera
    space is (x, y, z)."""
    corners = camera.data.view_frame(scene=scene)  # top right, bottom right, bottom left, top left
    right, bottom, left, top = corners[0].x, corners[1].y, corners[2].x, corners[0].y
    depth = corners[0].z
    xs = left + (np.arange(width) + 0.5) / width * (right - left)
    ys = bottom + (np.arange(height) + 0.5) / height * (top - bottom)
    return xs, ys, depth


def _shade(depsgraph, scene, width, height):
    """(depth, normal, combined): arrays of (height, width[, channels]),
    rows from the bottom, as a Render Result holds them."""
    camera = scene.camera
    to_world = camera.matrix_world.normalized()
    to_camera = to_world.inverted()
    origin = to_world.translation
    xs, ys, plane = _rays(scene, camera, width, height)
    depth = np.full((height, width), BACKGROUND_DEPTH, np.float32)
    normal = np.zeros((height, width, 3), np.float32)
    rotation = to_world.to_3x3()
    for row, y in enumerate(ys):
        for column, x in enumerate(xs):
            direction = (rotation @ Vector((x, y, plane))).normalized()
            hit, location, face_normal, _index, _object, _matrix = scene.ray_cast(
                depsgraph, origin, direction)
            if hit:
                depth[row, column] = -(to_camera @ location).z
                normal[row, column] = face_normal
    combined = np.ones((height, width, 4), np.float32)
    combined[..., :3] = np.abs(normal) * 0.8 + 0.1
    return depth, normal, combined


class RaycastEngine(bpy.types.RenderEngine):
    bl_idname = IDNAME
    bl_label = "HBAO test raycast"
    bl_use_postprocess = True

    def update_render_passes(self, scene=None, renderlayer=None):
        self.register_pass(scene, renderlayer, "Combined", 4, "RGBA", "COLOR")
        if renderlayer.use_pass_z:
            self.register_pass(scene, renderlayer, "Depth", 1, "Z", "VALUE")
        if renderlayer.use_pass_normal:
            self.register_pass(scene, renderlayer, "Normal", 3, "XYZ", "VECTOR")

    def render(self, depsgraph):
        scene = depsgraph.scene
        scale = scene.render.resolution_percentage / 100.0
        width = int(scene.render.resolution_x * scale)
        height = int(scene.render.resolution_y * scale)
        depth, normal, combined = _shade(depsgraph, scene, width, height)
        arrays = {"Combined": combined, "Depth": depth, "Normal": normal}
        layer_name = depsgraph.view_layer.name
        edges = np.linspace(0, height, BANDS + 1).astype(int)
        for first, last in zip(edges[:-1], edges[1:]):
            result = self.begin_result(0, int(first), width, int(last - first), layer=layer_name)
            for render_pass in result.layers[0].passes:
                if render_pass.name in arrays:
                    band = arrays[render_pass.name][first:last]
                    render_pass.rect = band.reshape(-1, render_pass.channels)
            self.end_result(result)


def register():
    bpy.utils.register_class(RaycastEngine)
