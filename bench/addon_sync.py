# SPDX-License-Identifier: GPL-2.0-or-later
"""What the add-on costs an artist's big file outside the AO: the sync of its
helper scenes (after every edit, at load, save and a render's end) and the
node timer's work (every quarter second with a window), against the file's
number of scenes. Run inside Blender with the add-on:

    blender -b --factory-startup --addons hbao --python bench/addon_sync.py -- 10 20 40
    python scripts/bpy_blender.py --addons hbao --python bench/addon_sync.py -- 10 20 40

For each count N: N scenes (an empty "Base" stays besides), every other one
with a compositor of Render Layers -> 4 HBAO nodes in a chain -> Composite,
the rest with a plain one (Render Layers -> Blur -> Composite). One sync
makes the helpers; then the median of 5 of each: the sync
(`handlers._sync_everything`, what the UI's timer runs after an edit), the
timer's refresh (`recomposite.refresh_changed`, no render done: its
per-tick cost) and `node_place.misplaced` for every HBAO node (what the
nodes' draw asks). Prints one line per count, `sync-bench: {json}`, with
the milliseconds."""
import json
import os
import sys
import time

import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "scripts"))
import blender_scenes  # noqa: E402
from bench_stats import median_ms  # noqa: E402
from hbao import compat, handlers, node, node_place, recomposite  # noqa: E402

NODES_PER_TREE = 4
ROUNDS = 5


def fill_scene(scene, with_hbao):
    camera = bpy.data.objects.new(f"{scene.name} camera", bpy.data.cameras.new(scene.name))
    scene.collection.objects.link(camera)
    scene.camera = camera
    for view_layer in scene.view_layers:
        blender_scenes.enable_passes(view_layer)
    compositor = blender_scenes.Compositor(scene)
    layers = compositor.render_layers()
    layers.scene = scene
    image = layers.outputs["Image"]
    for index in range(NODES_PER_TREE if with_hbao else 0):
        hbao = compositor.node("CompositorNodeHBAO")
        hbao.name = f"HBAO{index}"
        for socket in ("Depth", "Normal"):
            compositor.link(layers.outputs[socket], hbao.inputs[socket])
        compositor.link(image, hbao.inputs["Image"])
        image = hbao.outputs["Image"]
    if not with_hbao:
        blur = compositor.node("CompositorNodeBlur")
        compositor.link(image, blur.inputs["Image"])
        image = blur.outputs["Image"]
    compositor.composite(image)


def build(count):
    """`count` new scenes (those of the last count go, helpers too)."""
    base = bpy.data.scenes.get("Base") or bpy.data.scenes.new("Base")
    for window in bpy.context.window_manager.windows:
        window.scene = base
    for scene in list(bpy.data.scenes):
        if scene != base:
            bpy.data.scenes.remove(scene)
    for index in range(count):
        fill_scene(bpy.data.scenes.new(f"Shot {index:03d}"), with_hbao=index % 2 == 0)


def measure(count):
    build(count)
    start = time.perf_counter()
    handlers._sync_everything()
    first_sync = (time.perf_counter() - start) * 1000.0
    nodes = [member for scene in bpy.data.scenes
             for member in node.hbao_nodes(compat.compositor_tree(scene))]
    return {"blender": bpy.app.version_string, "scenes": count,
            "hbao_nodes": len(nodes), "first_sync_ms": round(first_sync, 1),
            "sync_ms": round(median_ms(handlers._sync_everything, ROUNDS), 1),
            "timer_refresh_ms": round(median_ms(
                lambda: recomposite.refresh_changed(in_background=True), ROUNDS), 2),
            "misplaced_all_ms": round(median_ms(
                lambda: [node_place.misplaced(member) for member in nodes], ROUNDS), 2)}


def main():
    texts = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if not all(text.isdigit() and 1 <= int(text) <= 1000 for text in texts):
        print("usage: ... --python bench/addon_sync.py -- [SCENES ...] (whole numbers, "
              f"1-1000; default 10 20 40), not {' '.join(texts)!r}", file=sys.stderr, flush=True)
        sys.exit(2)
    counts = [int(text) for text in texts] or [10, 20, 40]
    for count in counts:
        print("sync-bench:", json.dumps(measure(count)), flush=True)


if __name__ == "__main__":
    main()
