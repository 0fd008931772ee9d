# SPDX-License-Identifier: GPL-2.0-or-later
"""The time whose camera a render's passes show: the frame Blender renders,
which may be a subframe (frame_set(f, subframe)), and with Cycles' camera
motion blur the middle of the shutter, about which its samples' depths
average (the shutter opens at the frame with Position Start, closes there
with End). The engine evaluates the cameras there (job_inputs.py); the
extra renders, which Blender renders at the whole frame, are left out of
other times (extra_renders.py)."""
from . import compat


def of(main):
    """Frame and subframe, as one float, of `main`'s render now."""
    time = main.frame_current + main.frame_subframe
    render = main.render
    if render.use_motion_blur and render.engine == "CYCLES":
        shift = {"START": 0.5, "END": -0.5}.get(compat.motion_blur_position(main), 0.0)
        time += shift * render.motion_blur_shutter
    return time
