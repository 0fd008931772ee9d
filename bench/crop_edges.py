# SPDX-License-Identifier: GPL-2.0-or-later
"""How well two builds of libhbao guess what lies past a frame's edges, on
frames cut out of the quick benchmark's cached scenes: for each scene, 12
random crops (the same for both builds: seeded) are computed alone, through
the crop's own camera (hbao_camera_crop, as a border render's), and compared
with the whole frame's AO of the same build over the crop's pixels within 24
pixels of its edges (foreground only). The whole frame saw what lies past
the crop, so the difference is what the crop's edges cost: occluders cut off
(a direction that ends at the edge) or wrongly guessed (an edge surface
continued that does not go on, such as a curved body that the crop cuts).

    /usr/bin/python3 bench/crop_edges.py BEFORE.so AFTER.so

Needs the renders of `scripts/benchmark.sh --quick` in .cache/bench/."""
import random
import statistics
import sys

import numpy as np

import config
import metrics
import run_benchmark
import sweep
import two_builds

CROPS = 12
EDGE_PIXELS = 24
SEED = 7


def measure():
    """Mean |crop AO - whole AO| near each crop's edges, per scene, with the
    library in HBAO_LIBRARY, as JSON."""
    mode = config.QUICK
    native = sweep.load_native()
    renders = run_benchmark.REPO / ".cache/bench/renders" / run_benchmark.scene_sources_digest()
    jobs = {name: job["id"] for name, job in run_benchmark.accuracy_jobs(mode).items()}
    rng = random.Random(SEED)
    found = {}
    for scene in sorted(config.SCENES):
        if not (renders / scene).is_dir():
            sys.exit(f"no renders of {scene} in {renders}: run scripts/benchmark.sh --quick")
        data = sweep.SceneData(renders / scene, scene, mode, jobs)
        depth, normal, camera = (data.passes[key] for key in ("depth", "normal", "camera"))
        height, width = depth.shape
        params = {"radius": data.radius, "threads": 2}
        whole = native.compute_ao(depth, normal, params=params, camera=camera)
        foreground = metrics.foreground(depth)
        errors = []
        for _ in range(CROPS):
            w = rng.randint(width * 5 // 12, width * 3 // 4)
            h = rng.randint(height * 4 // 9, height * 4 // 5)
            x, y = rng.randint(0, width - w), rng.randint(0, height - h)
            crop = native.camera_crop(camera, width, height, x, y, w, h)
            ao = native.compute_ao(np.ascontiguousarray(depth[y:y + h, x:x + w]),
                                   np.ascontiguousarray(normal[y:y + h, x:x + w]),
                                   params=params, camera=crop)
            edge = np.ones((h, w), bool)
            edge[EDGE_PIXELS:-EDGE_PIXELS, EDGE_PIXELS:-EDGE_PIXELS] = False
            counted = edge & foreground[y:y + h, x:x + w]
            errors.append(float(np.abs(ao - whole[y:y + h, x:x + w])[counted].mean()))
        found[scene] = errors
    return found


def main():
    builds = two_builds.before_and_after(__file__, measure, __doc__)
    if builds is None:
        return
    before, after = builds
    print(f"Mean |crop AO - whole frame's AO| within {EDGE_PIXELS} px of the crop's edges, "
          f"{CROPS} crops a scene (seed {SEED}):\n")
    print("| scene | before: mean (worst crop) | after: mean (worst crop) | crops worse after |")
    print("|---|---|---|---|")
    for scene in before:
        b, a = before[scene], after[scene]
        worse = sum(1 for x, y in zip(b, a) if y > x)
        print(f"| {scene} | {statistics.mean(b):.4f} ({max(b):.4f}) | "
              f"{statistics.mean(a):.4f} ({max(a):.4f}) | {worse} of {len(b)} |")


if __name__ == "__main__":
    main()
