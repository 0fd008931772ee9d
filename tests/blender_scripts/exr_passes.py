# SPDX-License-Identifier: GPL-2.0-or-later
"""Prints, as one JSON line, the view layers and passes Blender itself finds in
multilayer EXRs: `blender -b --python exr_passes.py -- OUT.json A.exr B.exr ...`.

Multilayer EXRs have no Python pixel access; a compositor Image node showing
one still offers its view layers (the node's `layer` enum) and each layer's
passes (its enabled outputs), read by Blender's own OpenEXR code."""
import json
import re
import sys

import bpy

# A layer name no EXR holds: setting it makes Blender list the real ones.
IMPOSSIBLE_LAYER = "\x01no such layer"


def layer_names(node):
    try:
        node.layer = IMPOSSIBLE_LAYER
    except TypeError as error:
        listed = re.search(r"not found in \((.*)\)", str(error))
        if listed:
            return re.findall(r"'([^']*)'", listed.group(1))
    raise RuntimeError("Blender did not list the image's layers")


def describe(path, tree):
    node = tree.nodes.new("CompositorNodeImage")
    node.image = bpy.data.images.load(path, check_existing=False)
    description = {"type": node.image.type, "layers": {}}
    for name in layer_names(node):
        node.layer = name
        description["layers"][name] = [o.name for o in node.outputs if o.enabled]
    return description


def main():
    arguments = sys.argv[sys.argv.index("--") + 1:]
    out, paths = arguments[0], arguments[1:]
    scene = bpy.context.scene
    scene.use_nodes = True
    result = {path: describe(path, scene.node_tree) for path in paths}
    with open(out, "w", encoding="utf-8") as stream:
        json.dump(result, stream)


main()
