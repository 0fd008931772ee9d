# SPDX-License-Identifier: GPL-2.0-or-later
"""Inside Blender (with a window): times the viewport preview per frame. Run by
scripts/bench_viewport.py; see there.

For each size, the demo scene is drawn through its camera into a GPUOffScreen
of exactly that size (GPUOffScreen.draw_view3d, as the 3D view draws), then,
with that offscreen bound as in the POST_VIEW callback, the preview's
draw_preview() runs: depth read-back and upload, linearise, AO, blur,
composite. One pixel is read back after each timed call, which waits for the
GPU to finish (Python has no glFinish). Medians over repeated draws.
"""
import json
import sys
from pathlib import Path

import bpy
import gpu

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "scripts"))
import blender_scenes  # noqa: E402
from bench_stats import median_ms  # noqa: E402

SIZES = ((1280, 720), (1920, 1080))


def _arguments():
    args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    options = {"repeats": 7, "backend_check": False, "json": None}
    for index, arg in enumerate(args):
        if arg == "--repeats":
            options["repeats"] = int(args[index + 1])
        elif arg == "--backend-check":
            options["backend_check"] = True
        elif arg == "--json":
            options["json"] = args[index + 1]
    return options


def _sync(offscreen_framebuffer):
    offscreen_framebuffer.read_color(0, 0, 1, 1, 4, 0, "FLOAT")


def run(options):
    draw = sys.modules["hbao.viewport.draw"]
    pipeline = sys.modules["hbao.viewport.pipeline"]
    native = sys.modules["hbao.native"]
    print(f"renderer: {gpu.platform.renderer_get()} | {gpu.platform.vendor_get()} | "
          f"{gpu.platform.version_get()}")
    if options["backend_check"]:
        return []

    scene = blender_scenes.build_demo_scene(bpy.context.scene)
    window = bpy.context.window_manager.windows[0]
    area = next(a for a in window.screen.areas if a.type == "VIEW_3D")
    space = area.spaces.active
    space.shading.type = "SOLID"
    space.overlay.show_overlays = False
    region = next(r for r in area.regions if r.type == "WINDOW")
    depsgraph = bpy.context.evaluated_depsgraph_get()
    view_matrix = scene.camera.matrix_world.inverted()
    params = native.resolve_params({"radius": 0.6})
    rows = []
    for width, height in SIZES:
        projection_matrix = scene.camera.calc_matrix_camera(depsgraph, x=width, y=height)
        offscreen = gpu.types.GPUOffScreen(width, height)
        ao_pipeline = pipeline.AOPipeline()
        state = {"params": params}

        def draw_scene():
            offscreen.draw_view3d(scene, bpy.context.view_layer, space, region,
                                  view_matrix, projection_matrix, do_color_management=False)
            with offscreen.bind():
                _sync(gpu.state.active_framebuffer_get())

        def depth_round_trip():
            with offscreen.bind():
                framebuffer = gpu.state.active_framebuffer_get()
                depth = framebuffer.read_depth(0, 0, width, height)
                depth.dimensions = width * height
                gpu.types.GPUTexture((width, height), format="R32F", data=depth)

        def background_fraction():
            """Share of the frame without geometry: shows that the offscreen holds
            the scene's depth (all background would make the AO pass trivial)."""
            with offscreen.bind():
                depth = gpu.state.active_framebuffer_get().read_depth(0, 0, width, height)
            depth.dimensions = width * height
            sampled = depth[:][::97]
            return sum(1 for value in sampled if value >= 1.0) / len(sampled)

        def preview():
            with offscreen.bind():
                gpu.state.viewport_set(0, 0, width, height)
                draw.draw_preview(ao_pipeline, projection_matrix, state["params"], reuse=False)
                _sync(gpu.state.active_framebuffer_get())

        with bpy.context.temp_override(window=window, area=area, region=region):
            scene_ms = median_ms(draw_scene, options["repeats"], warm_up=True)
            draw_scene()  # the offscreen holds the scene's depth for the preview
            state["background"] = background_fraction()
            round_trip_ms = median_ms(depth_round_trip, options["repeats"], warm_up=True)
            preview_ms = median_ms(preview, options["repeats"], warm_up=True)
            state["params"] = dict(params, blur_size=0)
            preview_no_blur_ms = median_ms(preview, options["repeats"], warm_up=True)
            state["params"] = dict(params, half_resolution=True)
            preview_half_ms = median_ms(preview, options["repeats"], warm_up=True)
        rows.append({"size": f"{width}x{height}", "scene_ms": scene_ms,
                     "depth_read_upload_ms": round_trip_ms, "preview_ms": preview_ms,
                     "preview_no_blur_ms": preview_no_blur_ms,
                     "preview_half_ms": preview_half_ms,
                     "background_fraction": state.get("background")})
        offscreen.free()
    for row in rows:
        print(f"{row['size']}: background share of the depth buffer "
              f"{row['background_fraction']:.2f}")
    blur = f"blur {params['blur_size']}"
    print(f"{'size':>10} {'scene draw':>11} {'depth read+upload':>18} "
          f"{'preview (' + blur + ')':>17} {'preview (no blur)':>18} "
          f"{'half resolution':>16}   (median ms, {options['repeats']} draws; defaults, "
          f"radius 0.6; half resolution with {blur})")
    for row in rows:
        print(f"{row['size']:>10} {row['scene_ms']:>11.1f} {row['depth_read_upload_ms']:>18.1f} "
              f"{row['preview_ms']:>17.1f} {row['preview_no_blur_ms']:>18.1f} "
              f"{row['preview_half_ms']:>16.1f}")
    return rows


def main():
    options = _arguments()
    try:
        rows = run(options)
        if options["json"]:
            Path(options["json"]).write_text(json.dumps(rows, indent=2))
    finally:
        bpy.ops.wm.quit_blender()


bpy.app.timers.register(main, first_interval=0.5)
