# SPDX-License-Identifier: GPL-2.0-or-later
"""What the benchmark renders and measures, in quick and full mode.

Plain data, no bpy: read by the driver (run_benchmark.py). Every number that
decides what the report says is named here once.
"""
from dataclasses import dataclass, field

SCENES = ("interior", "bunny", "mechanical", "terrain")
# The headline's accuracy target: RMSE against Cycles' converged AO pass.
RMSE_TARGET = 0.05
# A setting is "as good as the method gets" on a scene when its RMSE is within
# this much of the best RMSE any swept setting reaches there (the margin is
# about the noise of a 256-sample Cycles reference, see docs/benchmark.md).
NEAR_BEST_MARGIN = 0.005
# Cycles samples per pixel of the depth/normal passes at the timing resolutions:
# both are written from the first sample.
PASS_SAMPLES = 1
# Depths from here on are the sky, scored nowhere (Cycles writes 1e10; every
# benchmark scene lies within 1e3 of its camera): metrics.foreground.
SKY_DEPTH = 1e9
# The resolutions that the timing table covers (720p to 4K).
TIMING_RESOLUTIONS = ((1280, 720), (1920, 1080), (2560, 1440), (3840, 2160))
# The scene whose passes are rendered at every timing resolution.
TIMING_SCENE = "interior"


@dataclass
class Mode:
    """One benchmark mode's sizes: accuracy resolution, sample counts, sweep."""
    name: str
    width: int
    height: int
    # Cycles' ground truth, and the sample counts of its time-against-error curve.
    reference_samples: int
    cycles_series: tuple
    eevee_samples: int
    # The converged screen-space reference: HBAO with this many directions and steps.
    converged_directions: int
    converged_steps: int
    # Timing: runs per setting (median), Cycles repeats up to this many samples.
    timing_runs: int
    cycles_repeat_below: int
    cycles_repeats: int
    # The main sweep (COSINE integration, NONE falloff: what Cycles measures).
    directions: tuple
    steps: tuple
    blur_sizes: tuple
    # The integration x falloff x angle bias sweep, on a smaller grid.
    mode_directions: tuple
    mode_steps: tuple
    angle_biases: tuple
    # The add-on render path: resolution and repeats.
    addon_resolution: tuple
    addon_repeats: int
    thread_counts: tuple = field(default=(1, 2))


QUICK = Mode(
    name="quick", width=480, height=270,
    reference_samples=256, cycles_series=(1, 2, 4, 8, 16, 32, 64), eevee_samples=16,
    converged_directions=32, converged_steps=32,
    timing_runs=3, cycles_repeat_below=8, cycles_repeats=3,
    directions=(2, 4, 6, 8, 12, 16), steps=(2, 4, 6, 8, 12, 16), blur_sizes=(0, 5, 9),
    mode_directions=(4, 8, 16), mode_steps=(4, 8), angle_biases=(0.0, 5.0, 10.0),
    addon_resolution=(1280, 720), addon_repeats=3,
)

FULL = Mode(
    name="full", width=960, height=540,
    reference_samples=1024, cycles_series=(1, 2, 4, 8, 16, 32, 64, 128, 256),
    eevee_samples=64,
    converged_directions=64, converged_steps=64,
    timing_runs=5, cycles_repeat_below=32, cycles_repeats=3,
    directions=(2, 4, 6, 8, 12, 16, 24), steps=(2, 4, 6, 8, 12, 16, 24),
    blur_sizes=(0, 5, 9, 15),
    mode_directions=(4, 8, 16), mode_steps=(4, 8, 16), angle_biases=(0.0, 5.0, 10.0),
    addon_resolution=(1920, 1080), addon_repeats=5,
)

MODES = {"quick": QUICK, "full": FULL}
