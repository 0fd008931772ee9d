# SPDX-License-Identifier: GPL-2.0-or-later
"""Accuracy past one depth layer (issue 12): HBAO's error against Cycles' AO
inside the frame, today, with a guard band (overscan) around the frame, with
a finite occluder thickness, and with a layer of back faces.

    /usr/bin/python3 bench/guard_band.py [--scenes bunny,interior] \\
        [--bands 0.125,0.25] [--thickness 0.25,0.5,1]

Renders (cached like run_benchmark.py's, in the same folder): each scene's
quick-mode reference (Cycles, 256 samples: the ground truth and today's
passes) and its Depth and Normal passes with a guard band of each fraction
of the width on every side (render_overscan.py: the frame is the centre of
the wider render, pixel for pixel). The AO of the wider render is computed
with the frame's camera widened by libhbao's hbao_camera_crop (negative
origin: overscan), as the CLI does for an EXR whose data window extends past
its display window, and then cropped to the frame. Every error is over the
frame's foreground pixels, with the library's default settings and the
scene's radius; thicknesses are given in units of that radius (no guard
band). Prints a Markdown table and writes .cache/bench/guard_band.json.
"""
import argparse
import json
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import config
import metrics
import report as figures
import run_benchmark
import sweep

# The comparison images (not in docs/benchmark/, which report.py empties).
FIGURES = run_benchmark.REPO / "docs" / "benchmark-layers"

DEFAULT_BANDS = (0.03125, 0.0625, 0.125, 0.25)
# Back faces are measured alone and with this guard band.
BACK_FACE_BANDS = (0.0, 0.0625)
# Median of this many compute_ao calls per timing.
TIMING_RUNS = 3
# Threads per compute_ao call (the benchmark machine has 2 shared cores).
THREADS = 2


def overscan_jobs(mode, bands):
    """Depth and Normal passes (1 Cycles sample: both are written from the
    first sample), without and with each guard band; the band-0 job times
    the plain passes render for the cost comparison."""
    jobs = {}
    for band in (0,) + tuple(bands):
        pixels = int(round(band * mode.width))
        jobs[pixels] = {"id": f"overscan{pixels}-{mode.width}x{mode.height}-s1-seed0",
                        "engine": "CYCLES", "width": mode.width, "height": mode.height,
                        "samples": config.PASS_SAMPLES, "seed": 0, "threads": THREADS,
                        "passes": ["depth", "normal"], "repeats": 3, "overscan": pixels}
    return jobs


def back_face_jobs(mode):
    """Depth of the back faces (every material overridden so that front faces
    are transparent; 1 sample), without and with a guard band."""
    jobs = {}
    for band in BACK_FACE_BANDS:
        pixels = int(round(band * mode.width))
        jobs[pixels] = {"id": f"backfaces{pixels}-{mode.width}x{mode.height}-s1-seed0",
                        "engine": "CYCLES", "width": mode.width, "height": mode.height,
                        "samples": config.PASS_SAMPLES, "seed": 0, "threads": THREADS,
                        "passes": ["depth"], "repeats": 3, "overscan": pixels,
                        "back_faces": True}
    return jobs


def render(script, scene, jobs, cache, env, bunny_json):
    cache.mkdir(parents=True, exist_ok=True)
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as handle:
        json.dump(list(jobs), handle)
    args = ["--scene", scene, "--jobs", handle.name, "--cache", str(cache),
            "--bunny-json", str(bunny_json)]
    try:
        run_benchmark.run_blender(script, args, env)
    finally:
        Path(handle.name).unlink()


def load(cache, job_id):
    meta = json.loads((cache / f"{job_id}.json").read_text())
    with np.load(cache / f"{job_id}.npz") as data:
        return meta, {key: data[key] for key in data.files}


def timed(native, depth, normal, camera, params, back_depth=None):
    times, ao = [], None
    for _ in range(TIMING_RUNS):
        start = time.perf_counter()
        ao = native.compute_ao(depth, normal, params=params, camera=camera,
                               back_depth=back_depth)
        times.append(time.perf_counter() - start)
    return ao, statistics.median(times)


def measure_scene(native, renders, scene, mode, overscans, thicknesses, backs):
    reference_id = run_benchmark.accuracy_jobs(mode)["reference"]["id"]
    meta, reference = load(renders / scene, reference_id)
    depth, normal, truth = reference["depth"], reference["normal"], reference["ao"]
    camera, radius = meta["camera"], meta["radius"]
    height, width = depth.shape
    mask = metrics.foreground(depth)
    margin = int(round(width * sweep.BORDER_FRACTION))
    inner = np.zeros_like(mask)
    inner[margin:height - margin, margin:width - margin] = True
    params = {"radius": radius, "threads": THREADS}

    def errors(ao):
        return {"rmse": metrics.error_stats(ao, truth, mask)["rmse"],
                "bias": metrics.error_stats(ao, truth, mask)["bias"],
                "inner_rmse": metrics.error_stats(ao, truth, mask & inner)["rmse"]}

    ao, seconds = timed(native, depth, normal, camera, params)
    images = {"today": ao}
    result = {"scene": scene, "radius": radius, "width": width, "height": height,
              "today": dict(errors(ao), seconds=seconds), "bands": [], "thickness": [],
              "back_faces": []}
    plain_render_s = None
    for pixels, job in sorted(overscans.items()):
        band_meta, passes = load(renders / f"{scene}-overscan", job["id"])
        if pixels == 0:
            plain_render_s = band_meta["time_s"]
            # The 1-sample passes are today's passes (the reference's, from its first sample).
            same = np.isclose(passes["depth"], depth, rtol=1e-6) | ~mask
            result["plain_passes_match_reference"] = float(np.mean(same))
            continue
        wide = native.camera_crop(camera, width, height, -pixels, -pixels, width + 2 * pixels,
                                  height + 2 * pixels)
        wide_ao, seconds = timed(native, passes["depth"], passes["normal"], wide, params)
        frame_ao = wide_ao[pixels:pixels + height, pixels:pixels + width]
        images[f"band{pixels}"] = frame_ao
        centre = passes["depth"][pixels:pixels + height, pixels:pixels + width]
        result["bands"].append(dict(
            errors(frame_ao), band_pixels=pixels, band_fraction=pixels / width, seconds=seconds,
            render_s=band_meta["time_s"], plain_render_s=plain_render_s,
            pixel_factor=(width + 2 * pixels) * (height + 2 * pixels) / (width * height),
            centre_matches_frame=float(np.mean(np.isclose(centre, depth, rtol=1e-6) | ~mask))))
    for pixels, job in sorted(backs.items()):
        back_meta, back = load(renders / f"{scene}-overscan", job["id"])
        if pixels == 0:
            ao, seconds = timed(native, depth, normal, camera, params, back["depth"])
        else:
            _meta, passes = load(renders / f"{scene}-overscan", overscans[pixels]["id"])
            wide = native.camera_crop(camera, width, height, -pixels, -pixels,
                                      width + 2 * pixels, height + 2 * pixels)
            wide_ao, seconds = timed(native, passes["depth"], passes["normal"], wide, params,
                                     back["depth"])
            ao = wide_ao[pixels:pixels + height, pixels:pixels + width]
        images[f"back{pixels}"] = ao
        result["back_faces"].append(dict(errors(ao), band_pixels=pixels, seconds=seconds,
                                         render_s=back_meta["time_s"]))
    band = int(round(BACK_FACE_BANDS[-1] * width))
    columns = [images["today"], images.get(f"band{band}"), images.get(f"back{band}")]
    if all(column is not None for column in columns):
        FIGURES.mkdir(parents=True, exist_ok=True)
        figures.write_comparison(truth, mask, columns, FIGURES / f"{scene}_layers.png")
        result["figure"] = f"benchmark-layers/{scene}_layers.png"
    for fraction in thicknesses:
        thickness = fraction * radius
        ao, seconds = timed(native, depth, normal, camera, dict(params, thickness=thickness))
        result["thickness"].append(dict(errors(ao), thickness=thickness,
                                        thickness_per_radius=fraction, seconds=seconds))
    return result


def table(results):
    lines = ["| scene | setting | RMSE | inner RMSE | bias | HBAO ms | pixels | passes render s |",
             "|---|---|---:|---:|---:|---:|---:|---:|"]
    for result in results:
        today = result["today"]
        lines.append(f"| {result['scene']} | today (no guard band) | {today['rmse']:.4f} | "
                     f"{today['inner_rmse']:.4f} | {today['bias']:+.4f} | "
                     f"{today['seconds'] * 1e3:.1f} | 1.00x | "
                     f"{result['bands'][0]['plain_render_s'] if result['bands'] else 0:.2f} |")
        for band in result["bands"]:
            lines.append(f"| {result['scene']} | guard band {band['band_fraction']:.3f} W "
                         f"({band['band_pixels']} px) | {band['rmse']:.4f} | "
                         f"{band['inner_rmse']:.4f} | {band['bias']:+.4f} | "
                         f"{band['seconds'] * 1e3:.1f} | {band['pixel_factor']:.2f}x | "
                         f"{band['render_s']:.2f} |")
        for entry in result["back_faces"]:
            band = (f" + guard band {entry['band_pixels']} px" if entry["band_pixels"]
                    else "")
            lines.append(f"| {result['scene']} | back faces{band} | {entry['rmse']:.4f} | "
                         f"{entry['inner_rmse']:.4f} | {entry['bias']:+.4f} | "
                         f"{entry['seconds'] * 1e3:.1f} | | {entry['render_s']:.2f} |")
        for entry in result["thickness"]:
            lines.append(f"| {result['scene']} | thickness {entry['thickness_per_radius']:g} "
                         f"x radius ({entry['thickness']:g}) | "
                         f"{entry['rmse']:.4f} | {entry['inner_rmse']:.4f} | "
                         f"{entry['bias']:+.4f} | {entry['seconds'] * 1e3:.1f} | 1.00x | |")
    return "\n".join(lines)


# A guard band "reaches the best" when its RMSE is within this of the widest
# band's (about the run-to-run noise of the 256-sample reference; config.py).
BAND_MARGIN = 0.001


def summary(results):
    """Per scene: the smallest guard band that reaches the best, and whether a
    finite thickness beats the infinite one; from the measured rows."""
    lines = []
    for result in results:
        today = result["today"]["rmse"]
        text = f"- **{result['scene']}**: today {today:.4f}"
        if result["bands"]:
            best = min(band["rmse"] for band in result["bands"])
            enough = min((b for b in result["bands"] if b["rmse"] <= best + BAND_MARGIN),
                         key=lambda b: b["band_pixels"])
            text += (f"; a guard band of {enough['band_pixels']} px "
                     f"({enough['band_fraction']:.3f} of the width, {enough['pixel_factor']:.2f}x "
                     f"the pixels) reaches {enough['rmse']:.4f} ({enough['rmse'] - today:+.4f})")
        for entry in result["back_faces"]:
            band = f" with a {entry['band_pixels']} px band" if entry["band_pixels"] else ""
            text += f"; back faces{band} {entry['rmse']:.4f} ({entry['rmse'] - today:+.4f})"
        if result["thickness"]:
            best = min(result["thickness"], key=lambda entry: entry["rmse"])
            if best["rmse"] < today:
                text += (f"; thickness {best['thickness_per_radius']:g} x radius gives "
                         f"{best['rmse']:.4f} ({best['rmse'] - today:+.4f})")
            else:
                text += "; no finite thickness measured beats the infinite one"
        lines.append(text + ".")
    return "\n".join(lines)


def images(results):
    return "\n\n".join(f"**{result['scene']}**\n\n![{result['scene']}]({result['figure']})"
                       for result in results if result.get("figure"))


def report(results, command, seconds):
    """docs/benchmark-layers.md: the table, how it was made and what it says."""
    return f"""<!-- SPDX-License-Identifier: GPL-2.0-or-later -->
# Accuracy past one depth layer: guard band and thickness

Generated by `{command}` (bench/guard_band.py; {platform.machine()}, wall time {seconds:.0f} s
with renders cached). Do not edit by hand: rerun the script.

Every row is HBAO with the library's defaults (4x16, blur 5, COSINE/NONE, bias 5) and each
scene's AO radius, against the quick benchmark's ground truth (Cycles' AO pass, 256 samples,
480x270; the scenes of docs/benchmark.md), over the frame's foreground pixels. *Inner RMSE*
leaves out a border of {sweep.BORDER_FRACTION} of the width. *Guard band*: Depth and Normal
rendered with that many extra pixels on every side (bench/render_overscan.py: resolution and
sensor raised together, so the frame is the centre of the wider render), AO computed over the
whole render with the frame's camera widened by `hbao_camera_crop` (as the CLI does for a data
window past the display window) and cropped to the frame. *Pixels*: the render's size against
the frame's, what its passes cost to render and HBAO to compute; *passes render s* is the
1-sample Depth/Normal render (mostly Blender's fixed cost per render at this size). *Thickness*
(hbao_params.thickness, in units of the scene's radius; no guard band): samples whose block
[z_s, z_s + thickness] lies wholly in front of the pixel are skipped. *Back faces*: a second
1-sample render whose materials are all overridden by the add-on's back-face material (front
faces transparent), whose Depth is the first back face behind each visible surface, passed to
`hbao_compute_layers` (an occluder covers only the angles between its front and its back point,
at least half the radius behind, and one beyond the radius whose view ray enters the radius
before its back occludes from there; docs/algorithm.md, "Two depth layers"); alone, and
with the guard band of the same width (its back faces rendered with the band). HBAO ms: median of
{TIMING_RUNS} runs, {THREADS} threads, on shared cores (noisy).

{summary(results)}

{table(results)}

Images per scene, top row: Cycles' AO (the truth) | today | guard band of 1/16 of the width |
back faces with that band; bottom row: each one's signed error against the truth (blue: darker,
red: brighter, saturated at {figures.ERROR_MAP_RANGE}).

{images(results)}
"""


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", default=",".join(config.SCENES))
    parser.add_argument("--bands", default=",".join(str(b) for b in DEFAULT_BANDS))
    parser.add_argument("--thickness", default="0.1,0.25,0.5,0.75,1",
                        help="comma-separated occluder thicknesses to measure, in units of "
                             "each scene's AO radius")
    parser.add_argument("--cache", default=str(run_benchmark.REPO / ".cache/bench"))
    parser.add_argument("--docs", default=str(run_benchmark.REPO / "docs/benchmark-layers.md"),
                        help="the Markdown report to write")
    args = parser.parse_args()
    started_all = time.perf_counter()
    mode = config.QUICK
    cache = Path(args.cache)
    bands = tuple(float(b) for b in args.bands.split(",") if b)
    thicknesses = tuple(float(t) for t in args.thickness.split(",") if t)
    user_scripts = Path(tempfile.mkdtemp(prefix="hbao-guard-band-"))
    env = run_benchmark.blender_environment(user_scripts)
    renders = cache / "renders" / run_benchmark.scene_sources_digest()
    reference = run_benchmark.accuracy_jobs(mode)["reference"]
    overscans = overscan_jobs(mode, bands)
    backs = back_face_jobs(mode)
    native = sweep.load_native()
    results = []
    for scene in (s for s in args.scenes.split(",") if s):
        started = time.perf_counter()
        render(run_benchmark.BENCH / "render_jobs.py", scene, [reference], renders / scene, env,
               cache / "bunny.json")
        render(run_benchmark.BENCH / "render_overscan.py", scene,
               list(overscans.values()) + list(backs.values()),
               renders / f"{scene}-overscan", env, cache / "bunny.json")
        run_benchmark.log(f"{scene}: renders in {time.perf_counter() - started:.0f} s")
        results.append(measure_scene(native, renders, scene, mode, overscans, thicknesses,
                                     backs))
    (cache / "guard_band.json").write_text(json.dumps(results, indent=1))
    command = "/usr/bin/python3 bench/guard_band.py " + " ".join(sys.argv[1:])
    Path(args.docs).write_text(report(results, command.strip(),
                                      time.perf_counter() - started_all))
    print(table(results))


if __name__ == "__main__":
    main()
