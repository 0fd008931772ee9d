#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""The viewport preview's GPU time without Blender, for a GPU machine where
no Blender runs (the `device` machine: no display, no Blender, Python 3.12).

    scripts/bench_viewport_gl.py [--repeats N] [--size WxH ...] [--json OUT]

Runs the add-on's own passes (addon/hbao/viewport/pipeline.py with the GLSL
of shader_sources.py, unchanged) on an EGL context of moderngl's, through
scripts/gl_blender_gpu.py, which stands in for the part of Blender's `gpu`
module they use. The depth is scripts/synthetic_depth.py's scene through its
camera, as in tests/blender_scripts/viewport_match.py. For each size and
setting it prints the median GPU time of the passes (OpenGL timer queries:
[halve,] normals, AO, blur, [upsample,] composite into an 8-bit sRGB
target as the view's overlay buffer is) and each pass's own (the blur's
and the composite's two draws summed), the wall time of a frame waited
for, the time of what draw.py has Blender do before them (the depth read
back from a depth buffer and uploaded again, then linearised: its GPU time
includes the GPU's waits for the CPU), and checks: the AO's difference from
the C library's on the same depth (mean, 99th percentile, largest;
tests/test_viewport.py allows 2e-4 and 2e-3 in Blender), the composited
AO's (into a float target), and the linearised depth's largest relative
error, so that a fast wrong shader shows. A timer query saturates at 2.1 s
(moderngl reads it as a 32-bit integer): such a time prints as nan.

Needs numpy, moderngl (Debian's python3-moderngl, which scripts/setup.sh
installs, or pip's), an EGL driver (libegl1) and the library (HBAO_LIBRARY,
else build/libhbao.so); scripts/gl_bundle.sh bundles all but numpy for a
bare GPU machine without network. In Blender, on the GPU that Blender
draws with, scripts/bench_viewport.py measures the whole preview.
"""
import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

try:
    import moderngl
except ImportError:
    sys.exit("bench_viewport_gl: moderngl is missing (scripts/setup.sh installs "
             "python3-moderngl; on a bare GPU machine, scripts/gl_bundle.sh)")

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "scripts"))
sys.path.insert(0, str(REPO / "addon"))
import gl_blender_gpu  # noqa: E402
from synthetic_depth import CAMERA, synthetic_depth  # noqa: E402

SETTINGS = (("defaults", {}),
            ("half resolution", {"half_resolution": 1}),
            ("8 x 6 + blur 15", {"directions": 8, "steps": 6, "blur_size": 15}),
            ("defaults, no blur", {"blur_size": 0}))


def _size(text):
    width, height = (int(v) for v in text.lower().split("x"))
    if width < 1 or height < 1:
        raise argparse.ArgumentTypeError(f"size must be positive, not {text}")
    return width, height


# moderngl reads a timer query into a signed 32-bit integer: a draw of
# 2^31 - 1 ns (2.1 s) or more reads as that (a software renderer at 4K).
_SATURATED_NS = 2 ** 31 - 1


def _milliseconds(nanoseconds):
    return float("nan") if nanoseconds >= _SATURATED_NS else nanoseconds / 1e6


def _timed(context, repeats, draw):
    """Median GPU milliseconds (timer query; NaN where saturated) and wall
    milliseconds of `draw`, each call waited for, after two unmeasured calls."""
    for _ in range(2):
        draw()
    context.finish()
    gpu_ms, wall_ms = [], []
    for _ in range(repeats):
        query = context.query(time=True)
        start = time.perf_counter()
        with query:
            draw()
        context.finish()
        wall_ms.append((time.perf_counter() - start) * 1e3)
        gpu_ms.append(_milliseconds(query.elapsed))
    return statistics.median(gpu_ms), statistics.median(wall_ms)


def _pass_times(repeats, draw, names):
    """Median GPU milliseconds of each pass of `draw` (by shader name in
    `names`: shader -> name), each draw timed on its own."""
    times = {}
    for _ in range(repeats):
        with gl_blender_gpu.timing_draws() as draws:
            draw()
        frame = {}
        for shader, nanoseconds in draws:
            frame[names[shader]] = frame.get(names[shader], 0.0) + _milliseconds(nanoseconds)
        for name, milliseconds in frame.items():
            times.setdefault(name, []).append(milliseconds)
    return {name: statistics.median(values) for name, values in times.items()}


def _depth_buffer(context, frame, depth, clip):
    """A depth-buffer framebuffer of `depth` as a perspective projection with
    clip distances `clip` stores it ([0, 1], cleared to 1 in the sky), and the
    projection's depth coefficients (projection.depth_coefficients)."""
    from hbao.viewport import projection
    near, far = clip
    matrix = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0],
              [0.0, 0.0, -(far + near) / (far - near), -2.0 * far * near / (far - near)],
              [0.0, 0.0, -1.0, 0.0]]
    z = np.clip(depth.astype(np.float64), near, far)
    ndc = (-(far + near) / (far - near) * -z + -2.0 * far * near / (far - near)) / z
    stored = np.where(depth >= 1e9, 1.0, 0.5 * ndc + 0.5).astype(np.float32)
    texture = context.depth_texture((frame.width, frame.height), data=stored[::-1].tobytes())
    framebuffer = context.framebuffer(depth_attachment=texture)
    return framebuffer, projection.depth_coefficients(matrix)


def _top_down(texture, width, height, components=1):
    """A float texture's texels, top row first."""
    texels = np.frombuffer(texture.texture.read(), dtype=np.float32)
    return texels.reshape(height, width, components)[::-1]


def _differences(a, b, prefix):
    difference = np.abs(a.astype(np.float64) - b)
    return {f"{prefix}mean_abs": float(difference.mean()),
            f"{prefix}p99_abs": float(np.percentile(difference, 99)),
            f"{prefix}max_abs": float(difference.max())}


def run(args):
    try:
        context = moderngl.create_standalone_context(backend="egl", require=430)
    except Exception as error:  # moderngl raises its own or glcontext's errors
        sys.exit(f"bench_viewport_gl: no OpenGL 4.3 context through EGL ({error}); "
                 f"scripts/setup.sh installs libegl1 and Mesa's driver")
    context.gc_mode = "auto"  # release textures and queries as Blender would
    gl_blender_gpu.install(context)
    import gpu  # noqa: PLC0415 (gl_blender_gpu's, installed above)
    from hbao import native  # noqa: PLC0415
    from hbao.viewport import pipeline, projection, shader_sources, shaders  # noqa: PLC0415
    renderer = f"{context.info['GL_RENDERER']} | {context.info['GL_VERSION']}"
    print(f"renderer: {renderer}")
    rows = []
    for width, height in args.size:
        frame = projection.frame_from_camera(CAMERA, width, height)
        depth = synthetic_depth(frame)
        sky = depth >= 1e9
        depth_texture = gpu.types.GPUTexture((width, height), format="R32F",
                                             data=depth[::-1].tobytes())
        # The composite draws into the view's overlay buffer (8-bit sRGB);
        # its result is checked in a float target, cleared, as
        # tests/blender_scripts/viewport_match.py reads it.
        overlay = gpu.types.GPUFrameBuffer(
            color_slots=gpu.types.GPUTexture((width, height), format="SRGB8_A8"))
        check_texture = gpu.types.GPUTexture((width, height), format="RGBA32F")
        check = gpu.types.GPUFrameBuffer(color_slots=check_texture)
        # What draw.py has Blender do first: read the view's depth buffer
        # back, upload it, linearise it.
        buffer, coefficients = _depth_buffer(context, frame, depth,
                                             (CAMERA["clip_start"], CAMERA["clip_end"]))
        fetch_pipeline = pipeline.AOPipeline()

        def fetch():
            stored = buffer.read(components=1, attachment=-1, dtype="f4")
            upload = gpu.types.GPUTexture((width, height), format="R32F", data=stored)
            return fetch_pipeline.linearize(upload, coefficients)

        fetch_gpu, fetch_wall = _timed(context, args.repeats, fetch)
        linear = _top_down(fetch(), width, height)[..., 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            relative = np.abs(linear.astype(np.float64) - depth) / depth
        fetch_row = {"fetch_gpu_ms": fetch_gpu, "fetch_wall_ms": fetch_wall,
                     "linear_depth_max_relative": float(relative[~sky].max()),
                     "linear_sky_zero": bool((linear[sky] == 0.0).all())}
        for name, overrides in SETTINGS:
            params = native.resolve_params(overrides)
            ao_pipeline = pipeline.AOPipeline()

            def draw(target=overlay):
                ao = ao_pipeline.ambient_occlusion(
                    depth_texture, frame, params,
                    depth_precision=shader_sources.FLOAT_DEPTH_PRECISION)
                with target.bind():
                    pipeline.composite(ao, params["strength"])
                return ao

            gpu_ms, wall_ms = _timed(context, args.repeats, draw)
            # the shaders by name (shaders.py compiles each once, on first use)
            names = {shader: name for name, shader in shaders._shaders.items()}
            passes = _pass_times(args.repeats, draw, names)
            check.clear(color=(0.0, 0.0, 0.0, 0.0))
            ao = draw(check)
            preview = np.clip(_top_down(ao, width, height)[..., 0], 0.0, 1.0)
            # over a white scene, out = colour + (1 - alpha)
            composited = _top_down(check_texture, width, height, 4)
            composited = composited[..., 0] + (1.0 - composited[..., 3])
            reference = native.compute_ao(depth, None, camera=CAMERA, params=params)
            rows.append({"size": f"{width}x{height}", "setting": name, "gpu_ms": gpu_ms,
                         "wall_ms": wall_ms, "passes_ms": passes, **fetch_row,
                         **_differences(preview, reference, ""),
                         **_differences(composited, reference, "composite_")})
    _print(rows)
    if args.json:
        Path(args.json).write_text(json.dumps({"renderer": renderer, "rows": rows}, indent=1))


def _print(rows):
    print(f"{'size':>9}  {'setting':<18} {'GPU ms':>7} {'wall ms':>8} {'mean |d|':>9} "
          f"{'p99 |d|':>9} {'max |d|':>8} {'composited p99 |d|':>18}")
    for row in rows:
        print(f"{row['size']:>9}  {row['setting']:<18} {row['gpu_ms']:7.2f} "
              f"{row['wall_ms']:8.2f} {row['mean_abs']:9.1e} {row['p99_abs']:9.1e} "
              f"{row['max_abs']:8.1e} {row['composite_p99_abs']:18.1e}")
    print("GPU ms of each pass (median; the blur's and the composite's two draws summed):")
    for row in rows:
        passes = "  ".join(f"{name} {ms:.2f}" for name, ms in row["passes_ms"].items())
        print(f"{row['size']:>9}  {row['setting']:<18} {passes}")
    print("The depth read back, uploaded and linearised (draw.py), ms (the GPU time includes "
          "its waits for the CPU):")
    for row in rows:
        if row["setting"] == SETTINGS[0][0]:
            print(f"{row['size']:>9}  GPU {row['fetch_gpu_ms']:.2f}  wall "
                  f"{row['fetch_wall_ms']:.2f}  linearised depth: largest relative error "
                  f"{row['linear_depth_max_relative']:.1e}, sky 0: "
                  f"{'yes' if row['linear_sky_zero'] else 'NO'}")
    if any(value != value for row in rows for value in [row["gpu_ms"], *row["passes_ms"].values()]):
        print("nan: a timer query saturated (a draw of 2.1 s or more); see the wall time")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=20)
    parser.add_argument("--size", type=_size, action="append")
    parser.add_argument("--json")
    args = parser.parse_args()
    args.size = args.size or [(1920, 1080), (3840, 2160)]
    if args.repeats < 1:
        parser.error("--repeats must be at least 1")
    os.environ.setdefault("HBAO_LIBRARY", str(REPO / "build" / "libhbao.so"))
    run(args)


if __name__ == "__main__":
    main()
