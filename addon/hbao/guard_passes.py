# SPDX-License-Identifier: GPL-2.0-or-later
"""The guard band at render time: the guard render's passes (guard_scene.py)
read back like the main render's, and a node's AO computed over the frame
with its band and cropped back to the frame (guard_geometry.py)."""
from . import camera as camera_model
from . import guard_geometry, guard_scene, handover, native
from .report import NodeMessage


class GuardPasses:
    """The guard render's depth and normal (top-down, like the main passes)."""

    def __init__(self, depth, normal, scale):
        self.depth = depth
        self.normal = normal
        self.scale = scale


def read(helper, main, jobs, timings):
    """GuardPasses for the jobs that want a band, or None; and messages for
    the nodes that wanted one that cannot be had."""
    wanting = [job for job in jobs if job.guard_band > 0.0]
    if not wanting:
        return None, []
    guard, scale_or_reason = guard_scene.read_guard(main, helper)
    if guard is None:
        return None, [NodeMessage(job.node_name, f"no guard band: {scale_or_reason}",
                                  "No guard band") for job in wanting]
    layer = guard.view_layers[0].name
    channels, guard_timings = handover.read_passes(guard, {layer: True})
    for name, seconds in guard_timings.items():
        timings[f"guard {name}"] = seconds
    return GuardPasses(channels[("depth", layer)], channels[("normal", layer)],
                       scale_or_reason), []


def compute(job, depth, normal, camera, guard):
    """A job's AO, bottom-up (H, W), from top-down passes: over the frame and
    its band when `guard` is given and the job wants a band."""
    if guard is None or job.guard_band <= 0.0:
        # The EXR's rows run top-down, a render pass bottom-up: views flipped, no copy.
        return native.compute_ao(depth[::-1], None if normal is None else normal[::-1],
                                 params=job.params, camera=camera, bottom_up=True)
    height, width = depth.shape
    band = guard_geometry.band_pixels(width, height, job.guard_band)
    columns, rows = band
    wide_depth = guard_geometry.extend(depth, guard.depth, band, guard.scale)
    wide_normal = None
    if normal is not None:
        wide_normal = guard_geometry.extend(normal, guard.normal, band, guard.scale)
    # The frame with its band is a crop reaching past the frame's image.
    wide_camera = camera_model.crop_camera(camera, width, height,
                                           (-columns, width + columns, -rows, height + rows))
    wide = native.compute_ao(wide_depth[::-1],
                             None if wide_normal is None else wide_normal[::-1],
                             params=job.params, camera=wide_camera, bottom_up=True)
    return guard_geometry.crop_band(wide, band)
