# SPDX-License-Identifier: GPL-2.0-or-later
"""The extra renders at render time (extra_renders.py): their passes read
back like the main render's, and a node's AO computed with the back faces'
depth and over the frame with its guard band, cropped back to the frame
(guard_geometry.py)."""
import numpy as np

from . import camera as camera_model
from . import extra_renders, guard_geometry, handover, native, render_threads
from .report import NodeMessage


class ExtraPasses:
    """What the extra renders gave for this frame (top-down, like the main
    passes): the guard's depth, normal and scale, the back faces' depth;
    None where not rendered or not wanted."""

    def __init__(self):
        self.guard_depth = self.guard_normal = self.guard_scale = None
        self.back_depth = None


def _read_kind(helper, main, kind, wanting, timings, messages):
    """(the extra scene, {"depth": ..., "normal": ...}) of `kind`, or None
    with a message for each job in `wanting`."""
    scene, reason = extra_renders.for_render(main, helper, kind)
    if scene is None:
        messages += [NodeMessage(job.node_name, f"no {kind.name}: {reason}",
                                 f"No {kind.name}") for job in wanting]
        return None
    layer = scene.view_layers[0].name
    channels, kind_timings = handover.read_passes(scene, {layer: kind.wants_normal},
                                                  threads=render_threads.count(main))
    for name, seconds in kind_timings.items():
        timings[f"{kind.name} {name}"] = seconds
    return scene, {key: channels[(key, layer)] for key, _layer in channels}


def read(helper, main, jobs, timings):
    """ExtraPasses for the jobs that want extra layers, or None; and messages
    for the nodes that wanted one that cannot be had."""
    extra, messages = ExtraPasses(), []
    wanting = [job for job in jobs if job.guard_band > 0.0]
    if wanting:
        found = _read_kind(helper, main, extra_renders.GUARD, wanting, timings, messages)
        if found is not None:
            scene, passes = found
            extra.guard_depth, extra.guard_normal = passes["depth"], passes["normal"]
            extra.guard_scale = scene.get(extra_renders.SCALE_KEY, 1.0)
    wanting = [job for job in jobs if job.back_faces]
    if wanting:
        found = _read_kind(helper, main, extra_renders.BACK, wanting, timings, messages)
        if found is not None:
            extra.back_depth = found[1]["depth"]
    if extra.guard_depth is None and extra.back_depth is None:
        return None, messages
    return extra, messages


def settings_of(job, extra):
    """What else than its arrays a job's AO depends on (ao_cache)."""
    guard_scale = extra.guard_scale if extra is not None else None
    return (job.with_normal, job.guard_band, job.back_faces, guard_scale)


def arrays_of(job, extra):
    """The extra renders' arrays a job's AO reads (ao_cache)."""
    if extra is None:
        return ()
    back = extra.back_depth if job.back_faces else None
    guard = (extra.guard_depth, extra.guard_normal) if job.guard_band > 0.0 else (None, None)
    return (back,) + guard


def extra_of(settings, arrays):
    """The ExtraPasses a job's AO read, back from its settings_of and its
    (depth, normal) + arrays_of (re-compositing from the AO cache)."""
    if len(arrays) <= 2:
        return None
    extra = ExtraPasses()
    extra.back_depth, extra.guard_depth, extra.guard_normal = arrays[2:5]
    extra.guard_scale = settings[3]
    return extra


def _flipped(array):
    return None if array is None else array[::-1]


def compute(job, depth, normal, camera, extra):
    """A job's AO, bottom-up (H, W), from top-down passes: with the back
    faces and over the frame and its band when `extra` has them and the job
    wants them."""
    back = extra.back_depth if extra is not None and job.back_faces else None
    params = dict(job.params, threads=job.threads, background_depth=camera_model.background_depth(
        camera, job.params["background_depth"]))
    if extra is None or extra.guard_depth is None or job.guard_band <= 0.0:
        # The EXR's rows run top-down, a render pass bottom-up: views flipped, no copy.
        return native.compute_ao(depth[::-1], _flipped(normal), params=params, camera=camera,
                                 bottom_up=True, back_depth=_flipped(back))
    height, width = depth.shape
    band = guard_geometry.band_pixels(width, height, job.guard_band)
    columns, rows = band
    wide_depth = guard_geometry.extend(depth, extra.guard_depth, band, extra.guard_scale)
    wide_normal = None
    if normal is not None:
        wide_normal = guard_geometry.extend(normal, extra.guard_normal, band, extra.guard_scale)
    wide_back = None
    if back is not None:  # the guard render has no back faces: unknown in the band
        unknown = np.zeros_like(back)
        wide_back = guard_geometry.extend(back, unknown, band, extra.guard_scale)
    # The frame with its band is a crop reaching past the frame's image.
    wide_camera = camera_model.crop_camera(camera, width, height,
                                           (-columns, width + columns, -rows, height + rows))
    wide = native.compute_ao(wide_depth[::-1], _flipped(wide_normal), params=params,
                             camera=wide_camera, bottom_up=True, back_depth=_flipped(wide_back))
    return guard_geometry.crop_band(wide, band)
