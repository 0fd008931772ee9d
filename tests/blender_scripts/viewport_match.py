# SPDX-License-Identifier: GPL-2.0-or-later
"""Runs inside Blender with a window (xvfb), or headless where Blender can
draw without one (bpy 5.2+, after gpu.init()): renders the viewport preview's
GLSL AO of synthetic depth images offscreen and the C library's AO of the same
images, and writes the per-case differences as JSON for
tests/test_viewport.py to judge.

    blender --factory-startup --python viewport_match.py -- OUT.json
"""
import json
import sys
from pathlib import Path

import bpy
import gpu
import numpy as np

REPO = Path(__file__).resolve().parents[2]
if str(REPO / "addon") not in sys.path:
    sys.path.insert(0, str(REPO / "addon"))
sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(REPO / "scripts"))

from hbao import native  # noqa: E402
from hbao.viewport import pipeline, projection, shader_sources  # noqa: E402
import timer_guard  # noqa: E402
from synthetic_depth import CAMERA, FLOOR_Y, synthetic_depth  # noqa: E402

if bpy.app.background and hasattr(gpu, "init"):
    gpu.init()  # 5.2+: an offscreen GPU context without a window

WIDTH, HEIGHT = 200, 150
# (depth, first columns) of posts four columns wide at the lens, each inside
# a 64-column span of the scene behind them (depths 3 to 8)
NEAR_POSTS = (0.3, (66, 130))
PERSPECTIVE_CAMERA = CAMERA
# Pixels 1.5x as tall as wide, lens shifted: the non-square, off-centre frame.
SHIFTED_CAMERA = dict(PERSPECTIVE_CAMERA, shift_x=0.1, shift_y=-0.05,
                      pixel_aspect_x=1.0, pixel_aspect_y=1.5)
ORTHOGRAPHIC_CAMERA = {"type": "ORTHO", "ortho_scale": 7.0, "sensor_fit": "AUTO"}

# The compared cases: (name, camera, parameters[, scene]); scene may set the
# floor's height ("floor_y", camera space), the image's "size" and
# "near_posts" (columns at the lens: NEAR_POSTS). Blur off
# shows the horizon search alone; blur on adds the two bilateral passes.
CASES = [
    ("persp_cosine", PERSPECTIVE_CAMERA, {"blur_size": 0}),
    ("persp_hbao", PERSPECTIVE_CAMERA, {"integration": "HBAO", "blur_size": 0}),
    ("persp_cosine_no_falloff", PERSPECTIVE_CAMERA,
     {"falloff": "NONE", "blur_size": 0, "directions": 6, "steps": 10, "radius": 1.5}),
    ("shifted_hbao_bias", SHIFTED_CAMERA,
     {"integration": "HBAO", "blur_size": 0, "angle_bias_degrees": 25.0}),
    ("ortho_cosine", ORTHOGRAPHIC_CAMERA, {"blur_size": 0, "radius": 0.8}),
    ("persp_cosine_blur", PERSPECTIVE_CAMERA, {"blur_size": 9, "blur_sharpness": 8.0}),
    ("persp_hbao_blur_strength", PERSPECTIVE_CAMERA,
     {"integration": "HBAO", "blur_size": 15, "blur_sharpness": 4.0, "strength": 2.0}),
    ("ortho_cosine_blur", ORTHOGRAPHIC_CAMERA, {"blur_size": 7, "radius": 0.8}),
    # Occluders 0.3 thick: the box and the sphere no longer darken the wall
    # behind them, but still the floor they stand on.
    ("persp_cosine_thickness", PERSPECTIVE_CAMERA, {"blur_size": 0, "thickness": 0.3}),
    # Posts at the lens, in blocks of the scene behind them: those blocks
    # march in classes of one step length each (hbao_block_classes).
    ("persp_cosine_near_posts", PERSPECTIVE_CAMERA, {"blur_size": 0}, {"near_posts": True}),
    # The eye 0.05 above the floor, V nearly in its plane: snapped samples on
    # the floor lie within gamma of V, and only "rising at least as steeply as
    # V" keeps them from counting as past the normal (docs/algorithm.md, "The
    # slice of a direction"). The floor must stay unoccluded: these cases
    # compare planes, not occlusion. A small radius keeps the samples within a
    # few pixels, where snapping moves them furthest off the slice: without the
    # rule, radius 0.1 puts false occlusion on about 7 times as many pixels as
    # radius 1 (measured).
    ("grazing_hbao", PERSPECTIVE_CAMERA,
     {"integration": "HBAO", "blur_size": 0, "radius": 0.1, "steps": 32}, {"floor_y": -0.05}),
    ("grazing_cosine", PERSPECTIVE_CAMERA, {"blur_size": 0, "radius": 0.1}, {"floor_y": -0.05}),
    # One row through the sphere: no vertical neighbour, so the normal is V made
    # perpendicular to the row's tangent (docs/algorithm.md, "Normals").
    ("one_row_hbao", PERSPECTIVE_CAMERA, {"integration": "HBAO", "blur_size": 0},
     {"size": (WIDTH, 1)}),
    # Half resolution: the search on every other pixel of every other row,
    # then the depth-aware upsample (csrc/lib/upsample.c), with and without
    # the blur that its guide normals steer; odd sizes give the half grid a
    # last column and row with no neighbour to the right or below.
    ("persp_cosine_half", PERSPECTIVE_CAMERA, {"blur_size": 0, "half_resolution": 1}),
    ("persp_hbao_half_blur", PERSPECTIVE_CAMERA,
     {"integration": "HBAO", "blur_size": 9, "blur_sharpness": 8.0, "half_resolution": 1}),
    ("ortho_cosine_half_odd", ORTHOGRAPHIC_CAMERA,
     {"blur_size": 5, "radius": 0.8, "half_resolution": 1}, {"size": (WIDTH + 1, HEIGHT + 1)}),
    # A view one pixel tall at half resolution: a half grid of one row.
    ("one_row_hbao_half", PERSPECTIVE_CAMERA,
     {"integration": "HBAO", "blur_size": 0, "half_resolution": 1}, {"size": (WIDTH + 1, 1)}),
    # Depths rounded to half floats (EEVEE's Depth pass): the library sees it
    # from the values and fits its tangents along runs of pixels; the preview
    # is told the rounding (as its depth buffer's, far away with a tiny Clip
    # Start) and fits them the same way.
    ("persp_cosine_half_depth", PERSPECTIVE_CAMERA, {"blur_size": 0}, {"half_depth": True}),
    ("ortho_hbao_half_depth", ORTHOGRAPHIC_CAMERA,
     {"integration": "HBAO", "blur_size": 0, "radius": 0.8}, {"half_depth": True}),
    # The scene 7400 times larger (a scene in centimetres), seen as the
    # preview sees it: its sky 0 (the cleared depth buffer), its background
    # depth float's largest (projection.BACKGROUND_DEPTH), so that the wall,
    # at 66600, is geometry; a band of sky at exactly 65504 just above the
    # wall, within the radius before it, is background all the same
    # (libhbao's HBAO_HALF_FLOAT_SKY), not a ledge that shades the wall's top.
    ("far_scene_cosine_blur", PERSPECTIVE_CAMERA,
     {"blur_size": 5, "radius": 7.4e3, "background_depth": projection.BACKGROUND_DEPTH},
     {"scale": 7.4e3}),
]
# The band of exactly 65504 of the scaled case: rows and columns of the sky.
HALF_FLOAT_SKY_BAND = (slice(6, None), slice(40, 160))
# The rounding of half floats relative to the value (csrc/lib/internal_hbao.h,
# HBAO_HALF_DEPTH_PRECISION).
HALF_DEPTH_PRECISION = 2.0 ** -10


def glsl_ao(depth, frame, params, depth_precision):
    """The preview pipeline's AO of `depth` (top row first): uploaded bottom-up as
    OpenGL wants, AO + blur passes, then the composite pass into a transparent
    float target, as into the view's overlay buffer: Blender lays that over
    the scene as out = colour + scene * (1 - alpha), so over a white scene
    the AO is 1 - alpha; read back and flipped to top-down."""
    height, width = depth.shape
    upload = gpu.types.Buffer("FLOAT", width * height, depth[::-1].ravel().tolist())
    depth_texture = gpu.types.GPUTexture((width, height), format="R32F", data=upload)
    ao_pipeline = pipeline.AOPipeline()
    ao_texture = ao_pipeline.ambient_occlusion(depth_texture, frame, params,
                                               depth_precision=depth_precision)
    result = gpu.types.GPUTexture((width, height), format="RGBA32F")
    framebuffer = gpu.types.GPUFrameBuffer(color_slots=result)
    with framebuffer.bind():
        framebuffer.clear(color=(0.0, 0.0, 0.0, 0.0))
        pipeline.composite(ao_texture, params["strength"])
        pixels = framebuffer.read_color(0, 0, width, height, 4, 0, "FLOAT")
    pixels.dimensions = width * height * 4
    colour_and_alpha = np.array(pixels, dtype=np.float32).reshape(height, width, 4)[::-1]
    return colour_and_alpha[:, :, 0] + (1.0 - colour_and_alpha[:, :, 3])


def blender_frame(camera, width, height):
    """The viewport path's frame: from the projection matrix Blender itself builds
    for `camera` (Object.calc_matrix_camera), as RegionView3D.window_matrix is in
    camera view."""
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.pixel_aspect_x = camera.get("pixel_aspect_x", 1.0)
    scene.render.pixel_aspect_y = camera.get("pixel_aspect_y", 1.0)
    data = bpy.data.cameras.new("MatchCamera")
    data.type = camera["type"]
    for name in ("lens", "sensor_width", "sensor_height", "sensor_fit", "shift_x", "shift_y",
                 "ortho_scale"):
        if name in camera:
            setattr(data, name, camera[name])
    data.clip_start, data.clip_end = CAMERA["clip_start"], CAMERA["clip_end"]
    obj = bpy.data.objects.new("MatchCamera", data)
    scene.collection.objects.link(obj)
    matrix = obj.calc_matrix_camera(bpy.context.evaluated_depsgraph_get(), x=width, y=height,
                                    scale_x=scene.render.pixel_aspect_x,
                                    scale_y=scene.render.pixel_aspect_y)
    bpy.data.objects.remove(obj)
    bpy.data.cameras.remove(data)
    return projection.frame_from_projection_matrix(matrix, width, height)


def frame_difference(a, b):
    """Largest difference of the frames' numbers relative to the pixel size."""
    return max(abs(getattr(a, n) - getattr(b, n)) / abs(a.pixel_size_x)
               for n in ("pixel_size_x", "pixel_size_y", "origin_x", "origin_y"))


def main():
    out_path = Path(sys.argv[sys.argv.index("--") + 1])
    report = {"renderer": gpu.platform.renderer_get(), "cases": {}}
    for name, camera, overrides, *scene in CASES:
        scene = scene[0] if scene else {}
        params = native.resolve_params(overrides)
        width, height = scene.get("size", (WIDTH, HEIGHT))
        frame = projection.frame_from_camera(camera, width, height)
        viewport_frame = blender_frame(camera, width, height)
        depth = synthetic_depth(frame, scene.get("floor_y", FLOOR_Y))
        if scene.get("scale"):
            sky = depth >= 1e9
            depth = np.where(sky, 0.0, depth * scene["scale"]).astype(np.float32)
            band = np.zeros_like(sky)
            band[HALF_FLOAT_SKY_BAND] = True
            depth[sky & band] = 65504.0
        if scene.get("near_posts"):
            for first in NEAR_POSTS[1]:
                depth[:, first:first + 4] = NEAR_POSTS[0]
        depth_precision = shader_sources.FLOAT_DEPTH_PRECISION
        if scene.get("half_depth"):
            depth = depth.astype(np.float16).astype(np.float32)
            depth_precision = HALF_DEPTH_PRECISION
        reference = native.compute_ao(depth, None, camera=camera,
                                      params=dict(params, threads=1))
        preview = glsl_ao(depth, viewport_frame, params, depth_precision)
        difference = np.abs(preview.astype(np.float64) - reference)
        report["cases"][name] = {
            "frame_vs_blender_matrix": frame_difference(frame, viewport_frame),
            "frames_same_projection": frame.perspective == viewport_frame.perspective,
            "mean_abs": float(difference.mean()),
            "p99_abs": float(np.percentile(difference, 99)),
            "max_abs": float(difference.max()),
            "reference_mean_ao": float(reference.mean()),
            "preview_mean_ao": float(preview.mean()),
            "occluded_fraction": float((reference < 0.9).mean()),
            "background_fraction": float(((depth >= 1e9) | (depth <= 0.0)).mean()),
            "finite": bool(np.isfinite(preview).all()),
        }
        print(name, report["cases"][name])
        if "--save" in sys.argv:
            np.save(out_path.with_name(f"{name}_ref.npy"), reference)
            np.save(out_path.with_name(f"{name}_glsl.npy"), preview)
            np.save(out_path.with_name(f"{name}_depth.npy"), depth)
    out_path.write_text(json.dumps(report, indent=2))


try:
    main()
finally:
    # --python-exit-code makes an exception exit Blender with an error code.
    # (Headless, the script's end ends Blender.)
    if not bpy.app.background:
        timer_guard.quit_blender()
