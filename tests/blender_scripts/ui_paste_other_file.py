# SPDX-License-Identifier: GPL-2.0-or-later
"""Run by tests/test_faults_ui.py in Blender's window (Xvfb): an HBAO node
(Radius 2, Steps 9) duplicated with Shift+D (DUPLICATED {json}: its group,
values, pass and links, after the add-on's sync), then the node and the
Render Layers node feeding it copied with the
node editor's Ctrl+C, File > New, pasted with Ctrl+V into the new file's
compositor (the clipboard's node then points at a group of the file just
closed: 3.4 crashed in the paste), linked again (the pasted Render Layers
node comes without its scene, and so without its links), and rendered.
Prints PASTED {json} once
the add-on's sync has run (the node's values and sockets), and RENDERED
{json} (the node's name and status); OUT_DIR/nodes_0001.exr holds its
outputs.

  blender --addons hbao --python ui_paste_other_file.py -- OUT_DIR
"""
import json
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ui_areas import node_editor, override  # noqa: E402

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))
import blender_scenes  # noqa: E402

out_dir = sys.argv[sys.argv.index("--") + 1]
steps = iter(range(100))
state = {}


def hbao_node(tree):
    return next(node for node in tree.nodes if node.bl_idname == "CompositorNodeHBAO")


def step():
    window = bpy.context.window_manager.windows[0]
    index = next(steps)
    if index == 0:  # the node, set and linked, in a first file
        scene = bpy.context.scene
        compositor = blender_scenes.Compositor(scene)
        layers = compositor.render_layers()
        hbao = compositor.node("CompositorNodeHBAO")
        for name in ("Image", "Depth", "Normal"):
            compositor.link(layers.outputs[name], hbao.inputs[name])
        compositor.composite(hbao.outputs["Image"])
        hbao.inputs["Radius"].default_value = 2.0
        hbao.inputs["Steps"].default_value = 9
        node_editor(window)
        return 0.5
    if index == 1:  # Shift+D of the node in its own file
        tree = bpy.context.scene.node_tree
        for node in tree.nodes:
            node.select = node.bl_idname == "CompositorNodeHBAO"
        with override(window, node_editor(window)):
            print("DUPLICATE", bpy.ops.node.duplicate(), flush=True)
        return 1.0  # the add-on's sync runs meanwhile
    if index == 2:
        tree = bpy.context.scene.node_tree
        duplicate = next(node for node in tree.nodes
                         if node.bl_idname == "CompositorNodeHBAO" and node.name != "HBAO")
        print("DUPLICATED", json.dumps({
            "radius": duplicate.inputs["Radius"].default_value,
            "steps": duplicate.inputs["Steps"].default_value,
            "group": getattr(duplicate.node_tree, "name", None),
            "pass": duplicate.pass_index, "linked": duplicate.inputs["Depth"].is_linked,
            "pending": any(key.startswith("hbao_pending") for key in duplicate.keys())}),
            flush=True)
        tree.nodes.remove(duplicate)
        return 0.5
    if index == 3:  # copy both, open a new file
        tree = bpy.context.scene.node_tree
        for node in tree.nodes:
            node.select = node.bl_idname in ("CompositorNodeHBAO", "CompositorNodeRLayers") \
                and not node.name.startswith("HBAO Passes")
        with override(window, node_editor(window)):
            print("COPY", bpy.ops.node.clipboard_copy(), flush=True)
        bpy.ops.wm.read_homefile(app_template="")
        return 1.0
    if index == 4:  # the new file's scene, its compositor (emptied) shown
        scene = blender_scenes.build_corner_scene(bpy.context.scene, (96, 64), "CYCLES", 4)
        compositor = blender_scenes.Compositor(scene)
        state["compositor"] = compositor
        state["output"] = compositor.file_output(out_dir, "nodes_")
        node_editor(window).spaces[0].node_tree = compositor.tree
        return 0.5
    if index == 5:
        with override(window, node_editor(window)):
            print("PASTE", bpy.ops.node.clipboard_paste(), flush=True)
        return 1.0  # the add-on's sync runs from its timer meanwhile
    scene = bpy.data.scenes["Scene"]
    tree = scene.node_tree
    if index == 6:
        hbao = hbao_node(tree)
        print("PASTED", json.dumps({
            "radius": hbao.inputs["Radius"].default_value,
            "steps": hbao.inputs["Steps"].default_value,
            "inputs": len(hbao.inputs),
            "group": getattr(hbao.node_tree, "name", None)}), flush=True)
        layers = next(node for node in tree.nodes if node.bl_idname == "CompositorNodeRLayers"
                      and not node.name.startswith("HBAO Passes"))
        layers.scene = scene
        state["compositor"].composite(hbao.outputs["Image"])
        for name in ("Image", "AO"):
            state["output"].add(f"{hbao.name}_{name}", hbao.outputs[name])
        scene.render.filepath = os.path.join(out_dir, "frame_")
        return 0.5
    if index == 7:  # the pasted Render Layers node lost its scene and links: the artist's
        layers = next(node for node in tree.nodes if node.bl_idname == "CompositorNodeRLayers"
                      and not node.name.startswith("HBAO Passes"))
        hbao = hbao_node(tree)
        for name in ("Image", "Depth", "Normal"):
            tree.links.new(layers.outputs[name], hbao.inputs[name])
        return 0.5
    if index == 8:
        bpy.ops.render.render(write_still=True, scene=scene.name)
        hbao = hbao_node(bpy.data.scenes["Scene"].node_tree)
        print("RENDERED", json.dumps({"node": hbao.name, "status": hbao.status}), flush=True)
    os._exit(0)


bpy.app.timers.register(step, first_interval=1.0, persistent=True)
