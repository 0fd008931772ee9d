# SPDX-License-Identifier: GPL-2.0-or-later
"""Accuracy of two builds of libhbao side by side, on the quick benchmark's
cached scenes: RMSE against the ray-traced reference for the benchmark's
settings grids (directions x steps x full/half x blur; integration x falloff
x angle bias), per scene, and how much the second build moves it. For a
change to the horizon search or the blur that is meant to keep the accuracy
(issue 11: within 2 %).

    /usr/bin/python3 bench/compare_accuracy.py BEFORE.so AFTER.so

Needs the renders of `scripts/benchmark.sh --quick` in .cache/bench/."""
import itertools
import statistics
import sys
from pathlib import Path

import config
import run_benchmark
import sweep
import two_builds

REPO = Path(__file__).resolve().parent.parent


def measure():
    """RMSE per setting and scene with the library in HBAO_LIBRARY, as JSON."""
    mode = config.QUICK
    native = sweep.load_native()
    renders = REPO / ".cache/bench/renders" / run_benchmark.scene_sources_digest()
    jobs = {name: job["id"] for name, job in run_benchmark.accuracy_jobs(mode).items()}
    rmse = {}
    for scene in sorted(config.SCENES):
        if not (renders / scene).is_dir():
            sys.exit(f"no renders of {scene} in {renders}: run scripts/benchmark.sh --quick")
        data = sweep.SceneData(renders / scene, scene, mode, jobs)
        for setting in itertools.chain(sweep.main_grid(mode), sweep.mode_grid(mode)):
            ao, _ = sweep.timed_compute(native, data.passes, setting, data.radius, 2, 1)
            key = sweep.setting_key(setting)
            rmse.setdefault(key, {})[scene] = sweep.metrics.error_stats(
                ao, data.truth, data.mask)["rmse"]
    return rmse


def main():
    builds = two_builds.before_and_after(__file__, measure, __doc__)
    if builds is None:
        return
    before, after = builds
    scenes = sorted(next(iter(before.values())))
    print("| setting | " + " | ".join(scenes) + " | mean change |")
    print("|---" * (len(scenes) + 2) + "|")
    changes, worst = [], 0.0
    for key in before:
        moved = [after[key][s] / before[key][s] - 1.0 for s in scenes]
        worst = max([worst] + [abs(m) for m in moved])
        mean_before = statistics.mean(before[key].values())
        change = statistics.mean(after[key].values()) / mean_before - 1.0
        changes.append(change)
        cells = " | ".join(f"{before[key][s]:.4f} -> {after[key][s]:.4f}" for s in scenes)
        print(f"| {key} | {cells} | {100 * change:+.2f} % |")
    print(f"\nmean RMSE over the scenes moves by {100 * min(changes):+.2f} % to "
          f"{100 * max(changes):+.2f} % over {len(changes)} settings; the largest move of one "
          f"scene's RMSE: {100 * worst:.2f} %")


if __name__ == "__main__":
    main()
