# SPDX-License-Identifier: GPL-2.0-or-later
"""Run by tests/test_addon.py: a File Output node of the test scripts
(scripts/file_output.py) given an input "Render", then one called "Image"
(the name of the node's first input before 5.0), each fed by another
Render Layers output. Prints INPUTS {json}: [input name, the output linked
to it] for each input with a name.

  blender -b --addons hbao --python file_output_inputs.py -- OUT_DIR
"""
import json
import os
import sys

import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))), "scripts"))
import blender_scenes  # noqa: E402

scene = blender_scenes.build_corner_scene(bpy.context.scene, (32, 32), "CYCLES", 1)
compositor = blender_scenes.Compositor(scene)
layers = compositor.render_layers()
files = compositor.file_output(sys.argv[sys.argv.index("--") + 1], "files_")
files.add("Render", layers.outputs["Image"])
files.add("Image", layers.outputs["Depth"])
print("INPUTS", json.dumps([[socket.name, socket.links[0].from_socket.name if socket.is_linked
                             else None] for socket in files.node.inputs if socket.name]),
      flush=True)
