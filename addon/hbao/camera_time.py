# SPDX-License-Identifier: GPL-2.0-or-later
"""The time whose camera a render's passes show: the frame Blender renders,
which may be a subframe (frame_set(f, subframe)), and with camera motion
blur (Cycles', EEVEE's) the middle of the shutter, about which the passes'
depths lie (the shutter opens at the frame with Position Start, closes
there with End; EEVEE's passes are its middle's exactly). The engine
evaluates the cameras there (job_inputs.py); the extra renders, which
Blender renders at the whole frame, are left out of other times
(extra_renders.py)."""
from . import compat


def of(main):
    """Frame and subframe, as one float, of `main`'s render now."""
    time = main.frame_current + main.frame_subframe
    blur = compat.motion_blur(main)
    if blur is not None:
        position, shutter = blur
        time += {"START": 0.5, "END": -0.5}.get(position, 0.0) * shutter
    return time
