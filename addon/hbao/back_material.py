# SPDX-License-Identifier: GPL-2.0-or-later
"""The material of the back faces' render (extra_renders.py): transparent
where a ray meets a front face, opaque at a back face, so that the render's
Depth is the nearest back face."""
import bpy

from . import compat, writes

NAME = ".HBAO back faces only"


def get_or_make():
    """The material, made (whole, writes.whole_or_removed) if missing."""
    material = bpy.data.materials.get(NAME)
    if material is not None:
        return material
    material = bpy.data.materials.new(NAME)
    with writes.whole_or_removed(lambda: bpy.data.materials.remove(material)):
        compat.ensure_material_nodes(material)
        nodes = material.node_tree.nodes
        nodes.clear()
        geometry = nodes.new("ShaderNodeNewGeometry")
        mix = nodes.new("ShaderNodeMixShader")
        transparent = nodes.new("ShaderNodeBsdfTransparent")
        opaque = nodes.new("ShaderNodeBsdfDiffuse")
        output = nodes.new("ShaderNodeOutputMaterial")
        links = material.node_tree.links
        links.new(geometry.outputs["Backfacing"], mix.inputs[0])
        links.new(transparent.outputs[0], mix.inputs[1])
        links.new(opaque.outputs[0], mix.inputs[2])
        links.new(mix.outputs[0], output.inputs["Surface"])
    return material


def remove_if_unused():
    material = bpy.data.materials.get(NAME)
    if material is not None and material.users == 0:
        bpy.data.materials.remove(material)
