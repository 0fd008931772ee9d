# SPDX-License-Identifier: GPL-2.0-or-later
"""Runs libhbao (through the add-on's ctypes binding) over a grid of settings
on one scene's cached passes: error against the references, and time."""
import itertools
import json
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import metrics

REPO = Path(__file__).resolve().parent.parent
# The border (a fraction of the width) left out of the "inner" RMSE, which
# shows how much of the error comes from occluders outside the image.
BORDER_FRACTION = 0.125


# The add-on's bpy-free modules (the binding, the parameters) import from here.
if str(REPO / "addon") not in sys.path:
    sys.path.insert(0, str(REPO / "addon"))


def load_native():
    """The add-on's binding (the package imports without bpy). Loads this
    checkout's build unless HBAO_LIBRARY names another library."""
    if str(REPO / "addon") not in sys.path:
        sys.path.insert(0, str(REPO / "addon"))
    from hbao import library_loading, native
    os.environ.setdefault("HBAO_LIBRARY",
                          str(REPO / "build" / library_loading.library_file_name("hbao")))
    return native


def setting_key(setting):
    """A short readable name: 8x6 half blur5 COSINE/NONE bias5."""
    text = f"{setting['directions']}x{setting['steps']}"
    if setting.get("half_resolution"):
        text += " half"
    text += f" blur{setting.get('blur_size', 0)}"
    return (f"{text} {setting.get('integration', 'COSINE')}/{setting.get('falloff', 'NONE')}"
            f" bias{setting.get('angle_bias_degrees', 5.0):g}")


def main_grid(mode):
    """directions x steps x half/full x blur, COSINE integration, NONE falloff."""
    for directions, steps, half, blur in itertools.product(
            mode.directions, mode.steps, (False, True), mode.blur_sizes):
        yield {"directions": directions, "steps": steps, "half_resolution": half,
               "blur_size": blur, "integration": "COSINE", "falloff": "NONE",
               "angle_bias_degrees": 5.0}


def mode_grid(mode):
    """integration x falloff x angle bias on a smaller grid, full resolution, blur 5."""
    for integration, falloff, bias, directions, steps in itertools.product(
            ("COSINE", "HBAO"), ("NONE", "QUADRATIC"), mode.angle_biases,
            mode.mode_directions, mode.mode_steps):
        yield {"directions": directions, "steps": steps, "half_resolution": False,
               "blur_size": 5, "integration": integration, "falloff": falloff,
               "angle_bias_degrees": bias}


def converged_settings(mode):
    """The converged screen-space references: very many directions and steps,
    no blur, full resolution, for each integration x falloff."""
    for integration, falloff in itertools.product(("COSINE", "HBAO"), ("NONE", "QUADRATIC")):
        yield {"directions": mode.converged_directions, "steps": mode.converged_steps,
               "half_resolution": False, "blur_size": 0, "integration": integration,
               "falloff": falloff, "angle_bias_degrees": 5.0}


def timed_compute(native, passes, setting, radius, threads, runs):
    """(ao, median seconds of `runs` calls) of compute_ao alone."""
    params = dict(setting, radius=radius, threads=threads)
    times, ao = [], None
    for _ in range(runs):
        start = time.perf_counter()
        ao = native.compute_ao(passes["depth"], passes["normal"], params=params,
                               camera=passes["camera"])
        times.append(time.perf_counter() - start)
    return ao, statistics.median(times)


class SceneData:
    """One scene's cached renders: passes, references, Cycles series, EEVEE."""

    def __init__(self, cache, scene, mode, job_ids):
        self.scene = scene
        self.meta = {}
        self.arrays = {}
        for name, job_id in job_ids.items():
            self.meta[name] = json.loads((cache / f"{job_id}.json").read_text())
            with np.load(cache / f"{job_id}.npz") as data:
                self.arrays[name] = {key: data[key] for key in data.files}
        reference = self.arrays["reference"]
        self.depth = reference["depth"]
        self.normal = reference["normal"]
        self.truth = reference["ao"]
        self.mask = metrics.foreground(self.depth)
        height, width = self.depth.shape
        margin = int(round(width * BORDER_FRACTION))
        self.inner = np.zeros_like(self.mask)
        self.inner[margin:height - margin, margin:width - margin] = True
        self.radius = self.meta["reference"]["radius"]
        self.camera = self.meta["reference"]["camera"]
        self.passes = {"depth": self.depth, "normal": self.normal, "camera": self.camera}


def inner_rmse(ao, data):
    """RMSE against the ground truth without the image's border."""
    return metrics.error_stats(ao, data.truth, data.mask & data.inner)["rmse"]


def run_scene(native, data, mode, log):
    """Every measurement of one scene; returns a JSON-able dict."""
    result = {"scene": data.scene, "radius": data.radius,
              "description": data.meta["reference"]["description"],
              "foreground_pixels": int(data.mask.sum()),
              "reference_samples": data.meta["reference"]["samples"],
              "reference_seconds": data.meta["reference"]["time_s"]}
    # Cycles at increasing sample counts (another seed than the reference).
    result["cycles"] = []
    result["border_fraction"] = BORDER_FRACTION
    for samples in mode.cycles_series:
        name = f"cycles{samples}"
        stats = metrics.error_stats(data.arrays[name]["ao"], data.truth, data.mask)
        result["cycles"].append(dict(stats, samples=samples, seconds=data.meta[name]["time_s"]))
    eevee = data.arrays["eevee"]["ao"]
    result["eevee"] = dict(metrics.error_stats(eevee, data.truth, data.mask),
                           samples=data.meta["eevee"]["samples"],
                           inner_rmse=inner_rmse(eevee, data))
    # The converged screen-space references.
    converged = {}
    result["converged"] = []
    for setting in converged_settings(mode):
        ao, seconds = timed_compute(native, data.passes, setting, data.radius, 2, 1)
        key = (setting["integration"], setting["falloff"])
        converged[key] = ao
        result["converged"].append(dict(metrics.error_stats(ao, data.truth, data.mask),
                                        setting=setting, key=setting_key(setting),
                                        seconds=seconds, inner_rmse=inner_rmse(ao, data)))
    # The sweeps: error against Cycles' ground truth and against the converged
    # reference of the same integration/falloff (the sampling error alone).
    result["sweep"] = []
    settings = list(main_grid(mode)) + list(mode_grid(mode))
    seen = set()
    for setting in settings:
        key = setting_key(setting)
        if key in seen:
            continue
        seen.add(key)
        ao, seconds = timed_compute(native, data.passes, setting, data.radius, 2,
                                    mode.timing_runs)
        entry = dict(metrics.error_stats(ao, data.truth, data.mask), setting=setting, key=key,
                     seconds=seconds, inner_rmse=inner_rmse(ao, data))
        own = converged[(setting["integration"], setting["falloff"])]
        entry["sampling_rmse"] = metrics.error_stats(ao, own, data.mask)["rmse"]
        result["sweep"].append(entry)
    log(f"{data.scene}: {len(result['sweep'])} settings measured")
    return result, converged
