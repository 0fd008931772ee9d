# SPDX-License-Identifier: GPL-2.0-or-later
"""Prints SAVED_LAYERS {scene: [view layer use, ...]} for the add-on's
scenes (named ".HBAO ...") of the file opened; with an argument, saves the
file to that path first and prints them after the save too (AFTER_SAVE)."""
import json
import sys

import bpy


def layers():
    return {scene.name: [layer.use for layer in scene.view_layers]
            for scene in bpy.data.scenes if scene.name.startswith(".HBAO")}


print("SAVED_LAYERS " + json.dumps(layers()))
args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
if args:
    bpy.ops.wm.save_as_mainfile(filepath=args[0], copy=True)
    print("AFTER_SAVE " + json.dumps(layers()))
