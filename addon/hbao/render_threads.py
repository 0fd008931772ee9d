# SPDX-License-Identifier: GPL-2.0-or-later
"""How many threads the add-on's work for a render uses (the AO, and the
read of the handed-over passes): as many as Blender renders that scene
with. `RenderSettings.threads` is Blender's own count: the command line's
`-t N`, else the Performance panel's Fixed count, else one per CPU. So a
farm worker limited with `blender -b -t 4` (or Fixed threads) stays within
that limit, as Blender's renderer does. bpy-free: reads the scene given."""
import os


def count(scene):
    """The threads for the AO and the pass read of `scene`'s render (>= 1).
    Blender's Auto count is every CPU online; where the process may run on
    fewer (taskset, a container's cpuset, a farm scheduler), those few."""
    threads = max(1, int(scene.render.threads))
    if scene.render.threads_mode == "AUTO":
        try:
            threads = min(threads, len(os.sched_getaffinity(0)))
        except (AttributeError, OSError):  # (not Linux)
            pass
    return threads
