# SPDX-License-Identifier: GPL-2.0-or-later
"""Run inside Blender by scripts/soak_blender.py, before the animation
render starts (`blender -b FILE --python soak_blender_probe.py -a`): after
each frame is written it prints one line

  HBAO-SOAK frame=N rss_kib=.. hwm_kib=.. anon_kib=.. swap_kib=.. cpu_s=..
            pre_cpu_s=.. pre_s=.. write_s=.. pid=..

(one line) read from this process itself, so the figures are the render's
own and not those of a wrapper: VmRSS, VmHWM, RssAnon and VmSwap from
/proc/self/status (RssAnon: heap and other private memory, which a leak
grows and which, unlike the mapped files in VmRSS, the kernel does not drop
under memory pressure short of swapping), the process's CPU time (user +
system, all threads) at the frame's render_pre and render_write, and
monotonic timestamps of both. The handlers are persistent, so they
survive the factory-settings reset and the file load that bpy_blender.py
does after this script has run."""
import os
import resource
import sys
import time

import bpy
from bpy.app.handlers import persistent

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from process_memory import status_kib  # noqa: E402  (scripts/process_memory.py)

TAG = "HBAO-SOAK"
# Self-test of the soak's memory check: this many KiB are allocated, touched
# and kept at every frame, a leak of known size (0: none).
INJECTED_LEAK_KIB = int(os.environ.get("HBAO_SOAK_INJECT_LEAK_KIB", "0"))
_frame_started = {}
_leaked = []


def _cpu_seconds():
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


@persistent
def _on_render_pre(scene, *_args):
    _frame_started["t"] = time.monotonic()
    _frame_started["cpu"] = _cpu_seconds()


@persistent
def _on_render_write(scene, *_args):
    now = time.monotonic()
    if INJECTED_LEAK_KIB:
        _leaked.append(bytearray(b"\x01" * (INJECTED_LEAK_KIB * 1024)))
    print(f"{TAG} frame={scene.frame_current} rss_kib={status_kib('VmRSS')} "
          f"hwm_kib={status_kib('VmHWM')} anon_kib={status_kib('RssAnon')} "
          f"swap_kib={status_kib('VmSwap')} cpu_s={_cpu_seconds():.3f} "
          f"pre_cpu_s={_frame_started.get('cpu', 0.0):.3f} "
          f"pre_s={_frame_started.get('t', now):.4f} write_s={now:.4f} pid={os.getpid()}",
          flush=True)


bpy.app.handlers.render_pre.append(_on_render_pre)
bpy.app.handlers.render_write.append(_on_render_write)
print(f"{TAG} probe installed pid={os.getpid()}", flush=True)
