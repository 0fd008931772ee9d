# SPDX-License-Identifier: GPL-2.0-or-later
"""Times the add-on's render path inside Blender: the same Cycles render with
and without an HBAO compositor node. Run by run_benchmark.py:

    blender -b --factory-startup --addons hbao --python bench/addon_timing.py -- \\
        '<json spec>'

Spec: scene, width, height, samples, repeats, node (the HBAO node's settings:
radius, directions, steps, blur_size, falloff, integration, half_resolution,
guard_band, back_faces); optional: passes, "production" to enable
blender_scenes.PRODUCTION_PASSES as well (the Render Result the hand-over saves grows with
them), threads.
Prints one line `bench-addon: {json}` with the render times in seconds
(without the node; with it, the AO computed each time; with it, the same
frame rendered again unchanged, the AO reused); the add-on's own console
line ("... pass hand-over N ms ...") is parsed by the driver from the same
output.
"""
import json
import os
import statistics
import sys
import time

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "scripts"))
import blender_scenes  # noqa: E402  (needs the paths above)
import scene_library  # noqa: E402

SOCKETS = {"radius": "Radius", "directions": "Directions", "steps": "Steps",
           "blur_size": "Blur Size", "angle_bias_degrees": "Angle Bias"}
PROPERTIES = ("falloff", "integration", "half_resolution", "guard_band", "back_faces")


def configure(scene, spec):
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = spec["samples"]
    scene.cycles.use_denoising = False  # Debian's Blender has no OpenImageDenoise
    scene.cycles.use_adaptive_sampling = False
    scene.render.resolution_x = spec["width"]
    scene.render.resolution_y = spec["height"]
    scene.render.resolution_percentage = 100
    scene.render.threads_mode = "FIXED"
    scene.render.threads = spec.get("threads", 2)
    layer = scene.view_layers[0]
    layer.use_pass_z = True
    layer.use_pass_normal = True
    if spec.get("passes") == "production":
        blender_scenes.enable_production_passes(layer)


def build_tree(scene, node_settings):
    """Render Layers -> (HBAO ->) the final image."""
    compositor = blender_scenes.Compositor(scene)
    layers = compositor.render_layers()
    if node_settings is None:
        compositor.composite(layers.outputs["Image"])
        return None
    hbao = compositor.node("CompositorNodeHBAO")
    for output in ("Image", "Depth", "Normal"):
        compositor.link(layers.outputs[output], hbao.inputs[output])
    for key, socket in SOCKETS.items():
        if key in node_settings:
            hbao.inputs[socket].default_value = node_settings[key]
    for key in PROPERTIES:
        if key in node_settings:
            setattr(hbao, key, node_settings[key])
    compositor.composite(hbao.outputs["Image"])
    return hbao


def timed_renders(scene, node_settings, repeats, nudge=False):
    """Render times after a warm-up. nudge: change the HBAO node's radius by
    a millionth before each render, so that the add-on computes the AO
    instead of reusing the last render's (ao_cache.py)."""
    hbao = build_tree(scene, node_settings)
    bpy.ops.render.render()  # warm-up: kernels, and the add-on's helper scene
    times = []
    for repeat in range(repeats):
        if nudge:
            nudged = node_settings["radius"] * (1 + 1e-6 * (repeat + 1))
            hbao.inputs["Radius"].default_value = nudged
        start = time.perf_counter()
        bpy.ops.render.render()
        times.append(time.perf_counter() - start)
    return times


def timed_refreshes(scene, hbao, radius, repeats):
    """Re-compositing with a new radius (recomposite.py): the time to bring
    the AO up to date from the last render's passes, as the add-on's timer
    does in a window (here called directly: `-b` has no timer)."""
    from hbao import recomposite
    times = []
    for repeat in range(repeats):
        hbao.inputs["Radius"].default_value = radius * (1.1 + 0.1 * repeat)
        start = time.perf_counter()
        if not recomposite.refresh_changed(in_background=True):
            raise RuntimeError("the AO was not brought up to date")
        times.append(time.perf_counter() - start)
    return times


def main():
    spec = json.loads(sys.argv[sys.argv.index("--") + 1])
    scene = bpy.context.scene
    spec_scene = scene_library.build(spec["scene"], spec.get("inputs", {}))
    configure(scene, spec)
    node = dict(spec["node"], radius=spec_scene.radius)
    without = timed_renders(scene, None, spec["repeats"])
    with_node = timed_renders(scene, node, spec["repeats"], nudge=True)
    # The same frame again, nothing changed: the AO is reused.
    unchanged = timed_renders(scene, node, spec["repeats"])
    hbao = next(n for n in blender_scenes.compat.compositor_tree(scene).nodes
                if n.bl_idname == "CompositorNodeHBAO")
    refreshed = timed_refreshes(scene, hbao, node["radius"], spec["repeats"])
    print("bench-addon: " + json.dumps({
        "without_node_s": without, "with_node_s": with_node, "unchanged_s": unchanged,
        "refresh_s": refreshed,
        "without_node_median_s": statistics.median(without),
        "with_node_median_s": statistics.median(with_node),
        "unchanged_median_s": statistics.median(unchanged),
        "refresh_median_s": statistics.median(refreshed)}), flush=True)


main()
