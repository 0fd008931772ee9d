# SPDX-License-Identifier: GPL-2.0-or-later
"""Renders the benchmark's passes of one scene in Blender and caches them as .npz.

    blender -b --factory-startup -noaudio --python bench/render_jobs.py -- \\
        --scene interior --jobs jobs.json --cache .cache/bench/renders \\
        [--bunny-json .cache/bench/bunny.json]

jobs.json is a list of jobs: {"id", "engine": "CYCLES"|"BLENDER_EEVEE", "width",
"height", "samples", "seed", "threads" (0 = all cores), "passes": subset of
["depth", "normal", "ao"], "repeats"}. Each job writes CACHE/<id>.npz (float32
arrays, row 0 = TOP image row: depth (H, W), normal (H, W, 3), ao (H, W)) and
CACHE/<id>.json (scene, camera as hbao.native's camera dict, radius, settings and
the render times in seconds). A job whose .json exists is skipped, so reruns only
render what is missing.

Getting pixels out: the render's passes go through a File Output node to
single-layer 32-bit EXRs in a scratch folder, which bpy.data.images.load reads
back with Python pixel access (a multilayer EXR would have none).
"""
import argparse
import json
import os
import shutil
import statistics
import sys
import time
from pathlib import Path

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "scripts"))
import blender_scenes  # noqa: E402  (needs the paths above)
import scene_library  # noqa: E402

# Cycles' pixel filter, in pixels. Nearly 0 so that every sample hits the
# pixel centre: the references then see the same surface as the Depth and
# Normal passes (written from the first sample), instead of an anti-aliased
# mix at edges that no depth-buffer method could reproduce.
PIXEL_FILTER_WIDTH = 0.01
# EEVEE's filter_size minimum, for the same reason.
EEVEE_FILTER_SIZE = 0.0
# Pass name -> Render Layers output socket.
PASS_SOCKETS = {"depth": "Depth", "normal": "Normal", "ao": "AO"}


def configure_cycles(scene, job, radius):
    scene.render.engine = "CYCLES"
    cycles = scene.cycles
    cycles.device = "CPU"
    cycles.samples = job["samples"]
    cycles.use_adaptive_sampling = False
    cycles.use_denoising = False  # Debian's Blender has no OpenImageDenoise
    # Only the AO pass is wanted: no bounces keep the Combined pass (which
    # Cycles always traces) as cheap as it gets, so the timing is that of AO.
    cycles.max_bounces = 0
    cycles.diffuse_bounces = 0
    cycles.glossy_bounces = 0
    cycles.transmission_bounces = 0
    cycles.volume_bounces = 0
    cycles.transparent_max_bounces = 0
    cycles.filter_width = PIXEL_FILTER_WIDTH
    cycles.seed = job.get("seed", 0)
    cycles.use_animated_seed = False
    # A black world is not sampled as a light: no shadow rays beside the AO
    # ray, so the render time is (nearly) that of the AO pass alone.
    scene.world.use_nodes = False
    scene.world.color = (0.0, 0.0, 0.0)
    scene.world.light_settings.distance = radius


def configure_eevee(scene, job, radius):
    scene.render.engine = "BLENDER_EEVEE"
    eevee = scene.eevee
    eevee.taa_render_samples = job["samples"]
    eevee.use_gtao = True
    eevee.gtao_distance = radius
    # The bounce approximation brightens AO by the albedo: off, to compare
    # pure visibility with Cycles' AO pass.
    eevee.use_gtao_bounce = False
    scene.render.filter_size = EEVEE_FILTER_SIZE


def configure_output(scene, job, scratch):
    scene.render.resolution_x = job["width"]
    scene.render.resolution_y = job["height"]
    scene.render.resolution_percentage = 100
    scene.render.pixel_aspect_x = 1.0
    scene.render.pixel_aspect_y = 1.0
    scene.render.use_compositing = True
    scene.render.threads_mode = "FIXED" if job.get("threads", 0) else "AUTO"
    if job.get("threads", 0):
        scene.render.threads = job["threads"]
    layer = scene.view_layers[0]
    layer.use_pass_z = "depth" in job["passes"]
    layer.use_pass_normal = "normal" in job["passes"]
    layer.use_pass_ambient_occlusion = "ao" in job["passes"]
    compositor = blender_scenes.Compositor(scene)
    layers = compositor.render_layers()
    layers.scene = scene
    # One folder per pass: Blender versions name single-image outputs differently.
    for name in job["passes"]:
        output = compositor.file_output(str(scratch / name), name, file_format="OPEN_EXR")
        output.node.format.color_mode = "RGB"
        output.add(name, blender_scenes.compat_nodes.pass_output(layers, PASS_SOCKETS[name]))
    compositor.composite(layers.outputs["Image"])


def read_exr(path, channels):
    image = bpy.data.images.load(str(path))
    try:
        image.colorspace_settings.name = "Non-Color"
        width, height = image.size
        pixels = np.empty(width * height * image.channels, dtype=np.float32)
        image.pixels.foreach_get(pixels)
        pixels = pixels.reshape(height, width, image.channels)[::-1]  # Blender: bottom row first
        return np.ascontiguousarray(pixels[..., :channels] if channels > 1 else pixels[..., 0])
    finally:
        bpy.data.images.remove(image)


def run_job(scene, spec, job, cache):
    scratch = cache / f"scratch-{job['id']}"
    shutil.rmtree(scratch, ignore_errors=True)
    scratch.mkdir(parents=True)
    if job["engine"] == "CYCLES":
        configure_cycles(scene, job, spec.radius)
    else:
        configure_eevee(scene, job, spec.radius)
    configure_output(scene, job, scratch)
    times = []
    for _ in range(max(1, job.get("repeats", 1))):
        start = time.perf_counter()
        bpy.ops.render.render()
        times.append(time.perf_counter() - start)
    arrays = {}
    for name in job["passes"]:
        files = sorted((scratch / name).glob("**/*.exr"))
        if not files:
            raise RuntimeError(f"job {job['id']}: no {name} pass written in {scratch}")
        arrays[name] = read_exr(files[-1], 3 if name == "normal" else 1)
    np.savez(cache / f"{job['id']}.npz", **arrays)
    meta = dict(job)
    meta.update(scene=spec.name, radius=spec.radius, description=spec.description,
                camera=blender_scenes.camera_description(scene), times_s=times,
                time_s=statistics.median(times), blender=bpy.app.version_string)
    # The .json is written last: its presence marks the job as done.
    (cache / f"{job['id']}.json").write_text(json.dumps(meta, indent=1))
    shutil.rmtree(scratch, ignore_errors=True)
    print(f"bench: {job['id']}: {statistics.median(times):.3f} s", flush=True)


def main(argv):
    parser = argparse.ArgumentParser(prog="render_jobs.py")
    parser.add_argument("--scene", required=True, choices=scene_library.SCENE_NAMES)
    parser.add_argument("--jobs", required=True)
    parser.add_argument("--cache", required=True)
    parser.add_argument("--bunny-json", default=None)
    args = parser.parse_args(argv)
    cache = Path(args.cache)
    cache.mkdir(parents=True, exist_ok=True)
    jobs = json.loads(Path(args.jobs).read_text())
    pending = [job for job in jobs if not (cache / f"{job['id']}.json").exists()]
    if not pending:
        print(f"bench: {args.scene}: all {len(jobs)} jobs cached")
        return
    scene = bpy.context.scene
    spec = scene_library.build(args.scene, {"bunny_json": args.bunny_json})
    for job in pending:
        run_job(scene, spec, job, cache)


if __name__ == "__main__":
    arguments = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    try:
        main(arguments)
    except Exception as error:  # report, then exit non-zero for the driver
        import traceback
        traceback.print_exc()
        print(f"bench: render failed: {error}", file=sys.stderr)
        sys.exit(1)
