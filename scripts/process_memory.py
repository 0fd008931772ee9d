# SPDX-License-Identifier: GPL-2.0-or-later
"""This process's own memory figures, for scripts that run inside Blender
(soak_blender_probe.py, bench_release_memory.py): read from
/proc/self/status, so they are Blender's and not a wrapper's. No bpy."""


def status_kib(field):
    """A field of /proc/self/status in KiB (VmRSS, VmHWM, RssAnon,
    VmSwap ...), or -1 where the system has no such field."""
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith(field + ":"):
                return int(line.split()[1])
    return -1
