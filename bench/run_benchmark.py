# SPDX-License-Identifier: GPL-2.0-or-later
"""The accuracy and speed benchmark against ray-traced AO (issue 5).

    /usr/bin/python3 bench/run_benchmark.py [--quick]

(scripts/benchmark.sh installs what it needs and runs this.) Steps:
 1. Blender renders each scene's passes and references into .cache/bench/
    (render_jobs.py; a cached job is not rendered again).
 2. libhbao runs over the settings sweep on each scene (sweep.py).
 3. compute_ao is timed at 720p..4K with 1 and 2 threads, and the add-on's
    render path is timed with and without the node (addon_timing.py).
 4. report.py writes docs/benchmark.md and its PNGs under docs/benchmark/.
"""
import argparse
import hashlib
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import config
import metrics
import report
import sweep
from hbao import timing_line  # sweep puts the add-on on sys.path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "scripts"))
import blenders  # noqa: E402

REPO = Path(__file__).resolve().parent.parent
BENCH = REPO / "bench"
BLENDER = os.environ.get("BLENDER", "blender")
# The HBAO node's settings that the add-on timing copies from the recommendation.
NODE_SETTINGS = ("directions", "steps", "blur_size", "angle_bias_degrees", "falloff",
                 "integration", "half_resolution")


def log(message):
    print(f"benchmark: {message}", flush=True)


def blender_environment(user_scripts):
    env = dict(os.environ)
    env["HBAO_LIBRARY"] = str(REPO / "build/libhbao.so")
    env["HBAO_EXR_LIBRARY"] = str(REPO / "build/libhbao_exr.so")
    env.update(blenders.user_folders(user_scripts))
    env["PYTHONUNBUFFERED"] = "1"
    return env


def run_blender(script, args, env, addon=False):
    command = [BLENDER, "-b", "--factory-startup", "-noaudio"]
    if addon:
        command += ["--addons", "hbao"]
    command += ["--python-exit-code", "1", "--python", str(script), "--"] + list(args)
    completed = subprocess.run(command, env=env, capture_output=True, text=True)
    if completed.returncode != 0:
        sys.stderr.write(completed.stdout[-4000:] + completed.stderr[-4000:])
        raise RuntimeError(f"Blender failed on {script.name} {' '.join(args)[:200]}")
    return completed.stdout


def cycles_job(mode, samples, repeats=None):
    """Cycles' AO pass at `samples` samples (seed 1, the reference's is 0),
    timed over `repeats` renders (by default mode.cycles_repeats below
    mode.cycles_repeat_below, else 1)."""
    if repeats is None:
        repeats = mode.cycles_repeats if samples < mode.cycles_repeat_below else 1
    return {"id": f"cycles-{mode.width}x{mode.height}-s{samples}-seed1-r{repeats}",
            "width": mode.width, "height": mode.height, "threads": 2, "engine": "CYCLES",
            "samples": samples, "seed": 1, "passes": ["ao"], "repeats": repeats}


def accuracy_jobs(mode):
    """name -> job for one scene: the reference with its passes, the Cycles
    series (another seed), EEVEE's GTAO."""
    size = {"width": mode.width, "height": mode.height, "threads": 2}
    jobs = {"reference": dict(size, id=f"cycles-{mode.width}x{mode.height}-"
                              f"s{mode.reference_samples}-seed0", engine="CYCLES",
                              samples=mode.reference_samples, seed=0,
                              passes=["depth", "normal", "ao"], repeats=1)}
    for samples in mode.cycles_series:
        jobs[f"cycles{samples}"] = cycles_job(mode, samples)
    jobs["eevee"] = dict(size, id=f"eevee-{mode.width}x{mode.height}-s{mode.eevee_samples}",
                         engine="BLENDER_EEVEE", samples=mode.eevee_samples, passes=["ao"],
                         repeats=1)
    return jobs


def equal_error(data, result, keys, mode, renders, env, bunny_json):
    """{key: Cycles' equal-error count and time, or None where the series'
    most samples do not reach its RMSE} for the sweep entries `keys` of one
    scene: metrics.equal_error_count over the Cycles series, rendering the
    whole counts between its powers of 2 that the search asks for. Each of
    those renders in a Blender of its own, whose first render is slower
    (interior, 5 samples: 0.256 s, then 0.218), so it is timed over
    mode.cycles_repeats renders whatever its count; the time line runs
    through every render made for any of the keys."""
    measured = {c["samples"]: (c["seconds"], c["rmse"]) for c in result["cycles"]}

    def rmse_at(samples):
        if samples not in measured:
            render = rendered(data.scene, cycles_job(mode, samples, mode.cycles_repeats),
                              renders, env, bunny_json)
            error = metrics.error_stats(render["ao"], data.truth, data.mask)["rmse"]
            measured[samples] = (render["meta"]["time_s"], error)
        return measured[samples][1]

    entries = {e["key"]: e for e in result["sweep"]}
    counts = {}
    for key in keys:
        try:
            counts[key] = metrics.equal_error_count(rmse_at, entries[key]["rmse"],
                                                    max(mode.cycles_series))
        except ValueError as error:  # the report says "more than" the series' most
            log(f"{data.scene} {key}: {error}")
            counts[key] = None
    times = sorted((n, t) for n, (t, _) in measured.items())  # every render, once all are made
    return {key: None if found is None else
            {"samples": found[0], "whole": found[1], "whole_rmse": measured[found[1]][1],
             "seconds": metrics.cycles_seconds_at(times, found[0])}
            for key, found in counts.items()}


def timing_jobs():
    return {f"{w}x{h}": {"id": f"passes-{w}x{h}", "engine": "CYCLES", "width": w, "height": h,
                         "samples": config.PASS_SAMPLES, "seed": 0, "threads": 2,
                         "passes": ["depth", "normal"], "repeats": 1}
            for w, h in config.TIMING_RESOLUTIONS}


def scene_sources_digest():
    """A short digest of the files that decide what a render shows: a change
    to a scene or to the render setup starts a fresh cache folder."""
    digest = hashlib.sha256()
    for name in ("scene_library.py", "render_jobs.py"):
        digest.update((BENCH / name).read_bytes())
    return digest.hexdigest()[:10]


def render_scene(scene, jobs, cache, env, bunny_json):
    cache.mkdir(parents=True, exist_ok=True)
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as handle:
        json.dump(list(jobs.values()), handle)
    try:
        args = ["--scene", scene, "--jobs", handle.name, "--cache", str(cache),
                "--bunny-json", str(bunny_json)]
        output = run_blender(BENCH / "render_jobs.py", args, env)
    finally:
        os.unlink(handle.name)
    for line in output.splitlines():
        if line.startswith("bench:"):
            log(f"{scene}: {line[7:]}")


def rendered(scene, job, cache, env, bunny_json):
    """A job's arrays and its meta (arrays["meta"]), rendered first where the
    cache lacks it (the .json, which render_jobs.py writes last)."""
    meta = cache / f"{job['id']}.json"
    if not meta.exists():
        render_scene(scene, {job["id"]: job}, cache, env, bunny_json)
    with np.load(cache / f"{job['id']}.npz") as data:
        arrays = {key: data[key] for key in data.files}
    arrays["meta"] = json.loads(meta.read_text())
    return arrays


def resolution_timings(native, cache, mode, settings):
    """compute_ao time (median of mode.timing_runs) at every timing resolution,
    1 and 2 threads, for each named setting."""
    rows = []
    for name, job in timing_jobs().items():
        meta = json.loads((cache / f"{job['id']}.json").read_text())
        with np.load(cache / f"{job['id']}.npz") as data:
            passes = {"depth": data["depth"], "normal": data["normal"], "camera": meta["camera"]}
        for label, setting in settings.items():
            row = {"resolution": name, "setting": label, "key": sweep.setting_key(setting)}
            for threads in mode.thread_counts:
                _, seconds = sweep.timed_compute(native, passes, setting, meta["radius"],
                                                 threads, mode.timing_runs)
                row[f"threads{threads}_s"] = seconds
            rows.append(row)
            log(f"timing {name} {label}: " + ", ".join(
                f"{t} thread(s) {row[f'threads{t}_s'] * 1000:.0f} ms" for t in mode.thread_counts))
    return rows


def addon_timing(mode, setting, env, bunny_json):
    spec = {"scene": config.TIMING_SCENE, "width": mode.addon_resolution[0],
            "height": mode.addon_resolution[1], "samples": config.PASS_SAMPLES,
            "repeats": mode.addon_repeats, "threads": 2,
            "inputs": {"bunny_json": str(bunny_json)},
            "node": {key: setting[key] for key in NODE_SETTINGS}}
    output = run_blender(BENCH / "addon_timing.py", [json.dumps(spec)], env, addon=True)
    result = None
    handovers, ao_times = [], []
    for line in output.splitlines():
        if line.startswith("bench-addon: "):
            result = json.loads(line[len("bench-addon: "):])
        figures = timing_line.parse(line)
        # The renders that computed the AO: not the unchanged frames (AO
        # reused) nor the refreshes (which also neither save nor read).
        if figures is not None and not figures["reused"] and not figures["recomposited"]:
            ao_times.append(figures["ao_ms"] / 1000.0)
            handovers.append(figures["handover_ms"] / 1000.0)
    if result is None or not handovers:
        raise RuntimeError("the add-on timing run printed no timings:\n" + output[-3000:])
    result.update(width=spec["width"], height=spec["height"], node=spec["node"],
                  handover_median_s=statistics.median(handovers),
                  ao_median_s=statistics.median(ao_times), addon_lines=len(handovers))
    return result


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small, fast mode (a few minutes)")
    parser.add_argument("--cache", default=str(REPO / ".cache/bench"))
    parser.add_argument("--docs", default=str(REPO / "docs"))
    parser.add_argument("--scenes", default=",".join(config.SCENES))
    args = parser.parse_args()
    mode = config.QUICK if args.quick else config.FULL
    cache = Path(args.cache)
    bunny_json = cache / "bunny.json"
    started = time.perf_counter()
    scenes = [s for s in args.scenes.split(",") if s]

    user_scripts = blenders.user_scripts_with_addon(tempfile.mkdtemp(prefix="hbao-bench-scripts-"))
    env = blender_environment(user_scripts)

    jobs = accuracy_jobs(mode)
    renders = cache / "renders" / scene_sources_digest()
    for stale in (cache / "renders").glob("*"):
        if stale.is_dir() and stale != renders:  # made from older scene sources
            shutil.rmtree(stale)
    for scene in scenes:
        render_scene(scene, jobs, renders / scene, env, bunny_json)
    timing_cache = renders / f"{config.TIMING_SCENE}-timing"
    render_scene(config.TIMING_SCENE, timing_jobs(), timing_cache, env, bunny_json)
    render_seconds = time.perf_counter() - started
    log(f"renders done after {render_seconds:.0f} s")

    native = sweep.load_native()
    results = {"mode": mode.name, "width": mode.width, "height": mode.height,
               "library_version": native.library_version(), "scenes": {},
               "render_s": render_seconds}
    images = {}
    for scene in scenes:
        data = sweep.SceneData(renders / scene, scene, mode,
                               {name: job["id"] for name, job in jobs.items()})
        results["scenes"][scene], converged = sweep.run_scene(native, data, mode, log)
        images[scene] = (data, converged)
    log(f"sweeps done after {time.perf_counter() - started:.0f} s")

    recommended = report.recommend(results)
    results["recommended"] = recommended
    for scene in scenes:
        result = results["scenes"][scene]
        keys = {report.headline_entry(result)[0]["key"], recommended["key"]}
        result["equal_error"] = equal_error(images[scene][0], result, keys, mode,
                                            renders / scene, env, bunny_json)
    log(f"equal-error counts done after {time.perf_counter() - started:.0f} s")
    timing_settings = {"recommended": recommended["setting"],
                       "shipped defaults": report.SHIPPED_DEFAULT,
                       "16x16 full": dict(report.SHIPPED_DEFAULT, directions=16, steps=16)}
    results["resolutions"] = resolution_timings(native, timing_cache, mode, timing_settings)
    # The node as it ships.
    results["addon"] = addon_timing(mode, report.SHIPPED_DEFAULT, env, bunny_json)
    log(f"add-on path: {results['addon']['with_node_median_s']:.2f} s with the node, "
        f"{results['addon']['without_node_median_s']:.2f} s without")
    results["wall_s"] = time.perf_counter() - started
    (cache / f"results-{mode.name}.json").write_text(json.dumps(results, indent=1))
    report.write(results, images, native, Path(args.docs))
    log(f"done in {results['wall_s']:.0f} s: {args.docs}/benchmark.md")


if __name__ == "__main__":
    main()
