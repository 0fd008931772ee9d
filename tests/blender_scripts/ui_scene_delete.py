# SPDX-License-Identifier: GPL-2.0-or-later
"""Run by tests/test_faults_ui.py in Blender's window (Xvfb): a scene with an
HBAO node, Scene > New of KIND (NEW, EMPTY, LINK_COPY or FULL_COPY: the copies
carry the node; the test runs NEW and FULL_COPY), then Scene > Delete of the
first scene while the window shows it. Blender shows the scene before the
deleted one in its list: the add-on's helper scenes, whose names start with
a dot, come first. Prints
SCENES {json} once the add-on's sync has run: the window's scene, the
scenes left (name: internal?) and, for each artist scene, the helper its
managed node renders. With the copy still holding a node, renders it to
OUT_DIR/nodes_0001.exr and prints RENDERED {json}. KIND NEW_SAVED: NEW, the
node with a guard band and back faces, and the file saved at once after the
Delete, before any sync: prints SAVED {json}, the scenes in the file.
KIND SWITCH: no new scene; the window is switched to the helper scene, as
the scene selector's search (which finds ".HBAO ...") does, then SCENES.

  blender --addons hbao --python ui_scene_delete.py -- KIND OUT_DIR
"""
import importlib
import json
import os
import sys
import traceback

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ui_areas import node_editor, override  # noqa: E402

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))
import blender_scenes  # noqa: E402

kind, out_dir = sys.argv[sys.argv.index("--") + 1:][:2]
steps = iter(range(100))
helper_lookup = sys.modules["hbao.helper_lookup"]
window_scenes = importlib.import_module("hbao.window_scenes")
switched = []


def scenes():
    managed = {}
    for scene in bpy.data.scenes:
        node = helper_lookup.managed_node(getattr(scene, "node_tree", None))
        if node is not None:
            managed[scene.name] = node.scene.name if node.scene else None
    return {"window": bpy.context.window_manager.windows[0].scene.name,
            "scenes": {scene.name: window_scenes.is_internal(scene)
                       for scene in bpy.data.scenes},
            "managed": managed}


def step():
    try:
        return _step()
    except Exception:  # a failure must end Blender, not leave it open
        traceback.print_exc()
        os._exit(1)


def _switch_to_the_helper(window):
    """SWITCH: once the sync has made the helper, the window shows it."""
    managed = helper_lookup.managed_node(bpy.data.scenes["Scene"].node_tree)
    if managed is None:
        return 0.5  # the sync has not run yet
    window.scene = managed.scene  # through RNA, as the scene selector sets it
    print("SWITCHED", managed.scene.name, flush=True)
    switched.append(managed.scene.name)
    return 2.0


def _step():
    window = bpy.context.window_manager.windows[0]
    index = next(steps)
    if index == 0:
        scene = blender_scenes.build_corner_scene(bpy.context.scene, (96, 64), "CYCLES", 4)
        hbao = blender_scenes.hbao_test_tree(scene, out_dir, "HBAO")
        if kind == "NEW_SAVED":
            hbao.guard_band, hbao.back_faces = 10.0, True
        scene.render.filepath = os.path.join(out_dir, "frame_")
        node_editor(window)
        return 1.0  # the add-on's sync makes the helper meanwhile
    if kind == "SWITCH":
        if not switched and index < 20:
            return _switch_to_the_helper(window)
    elif index == 1:
        with override(window, node_editor(window)):
            print("NEW", bpy.ops.scene.new(type=kind.replace("_SAVED", "")), flush=True)
        return 1.0
    elif index == 2:
        window.scene = bpy.data.scenes["Scene"]
        return 1.0
    elif index == 3:
        with override(window, node_editor(window)):
            print("DELETE", bpy.ops.scene.delete(), flush=True)
        if kind == "NEW_SAVED":
            os.makedirs(out_dir, exist_ok=True)
            path = os.path.join(out_dir, "saved.blend")
            bpy.ops.wm.save_as_mainfile(filepath=path, copy=True)
            with bpy.data.libraries.load(path) as (saved, _unused):
                print("SAVED", json.dumps(sorted(saved.scenes)), flush=True)
        return 2.0
    try:  # (an exception here must not leave Blender open)
        state = scenes()
        print("SCENES", json.dumps(state), flush=True)
        if "Scene.001" in state["managed"]:  # the copy, still with its node
            scene = bpy.data.scenes["Scene.001"]
            bpy.ops.render.render(write_still=True, scene=scene.name)
            hbao = next(node for node in scene.node_tree.nodes
                        if node.bl_idname == "CompositorNodeHBAO")
            print("RENDERED", json.dumps({"node": hbao.name, "status": hbao.status}),
                  flush=True)
    finally:
        os._exit(0)


bpy.app.timers.register(step, first_interval=1.0, persistent=True)
