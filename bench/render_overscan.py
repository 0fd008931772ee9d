# SPDX-License-Identifier: GPL-2.0-or-later
"""Renders a scene's Depth and Normal passes with overscan: the benchmark's
frame plus a guard band of `overscan` pixels on every side (guard_band.py).

    blender -b --factory-startup -noaudio --python bench/render_overscan.py -- \\
        --scene bunny --jobs jobs.json --cache DIR [--bunny-json FILE]

The jobs are render_jobs.py's, each with an "overscan" key (pixels) and
optionally "back_faces" (true: every material overridden by the add-on's
back-face material, so Depth holds the first back face; extra_renders.py). The
frame grows by 2 * overscan in both directions and the camera's fitted sensor
side (or ortho scale) grows with it, so that every pixel of the frame keeps
its view ray: the frame is the centre of the wider render. Each job's .json
holds the camera Blender rendered with (the wide one).
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import render_jobs  # noqa: E402  (needs the path above)

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "addon"))

_frame_output = render_jobs.configure_output


def _widened_output(scene, job, scratch):
    """render_jobs.configure_output, then the frame widened by the guard band."""
    _frame_output(scene, job, scratch)
    if job.get("back_faces"):
        from hbao import back_material
        layer = scene.view_layers[0]
        layer.material_override = back_material.get_or_make()
        layer.pass_alpha_threshold = 0.5
        scene.cycles.transparent_max_bounces = 64
    band = job["overscan"]
    camera = scene.camera.data
    if band == 0:
        return
    if camera.sensor_fit != "AUTO" or camera.shift_x or camera.shift_y:
        raise RuntimeError("the overscan render assumes an AUTO-fit camera without shift")
    width, height = job["width"], job["height"]
    if width < height:
        raise RuntimeError("the overscan render assumes a landscape frame")
    # AUTO fits the wider side, the width, before and after: the sensor grows
    # with it and each pixel keeps its size.
    scale = (width + 2 * band) / width
    camera.sensor_width *= scale
    camera.ortho_scale *= scale
    scene.render.resolution_x = width + 2 * band
    scene.render.resolution_y = height + 2 * band


_run_job = render_jobs.run_job


def _run_overscan_job(scene, spec, job, cache):
    """render_jobs.run_job, with the camera put back for the next job."""
    camera = scene.camera.data
    saved = (camera.sensor_width, camera.ortho_scale)
    try:
        _run_job(scene, spec, job, cache)
    finally:
        camera.sensor_width, camera.ortho_scale = saved
        scene.view_layers[0].material_override = None


if __name__ == "__main__":
    render_jobs.configure_output = _widened_output
    render_jobs.run_job = _run_overscan_job
    arguments = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    try:
        render_jobs.main(arguments)
    except Exception as error:
        import traceback
        traceback.print_exc()
        print(f"bench: render failed: {error}", file=sys.stderr)
        sys.exit(1)
