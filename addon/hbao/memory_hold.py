# SPDX-License-Identifier: GPL-2.0-or-later
"""When the library's working memory goes back to the system after a render.

The library keeps a frame's buffers (about 24 bytes a pixel: 50 MB at
1080p, at most 512 MB) for its next call; hbao_release_memory() hands them
back. Released at each render's end, the next render's first AO faults
every page in again: about 30 ms of a 1080p F12 render's AO on the
project's VMs (docs/speed.md, session 68). So:

- In `-b` (and bpy), a render's end releases them at once: an animation
  keeps them from frame to frame and releases them after its last, and the
  process usually ends soon after anyway.
- In a window, where the artist renders again after a look or a change,
  they are held HOLD_S seconds after the last render ended, then released
  by a timer (render handlers run in the render job's thread, where no
  timer may be started); a render running then pushes the release back.
  Disabling the add-on releases them at once.
"""
import time

import bpy

from . import native
from .callback_guard import never_raises

# How long a window's Blender holds the memory after a render has ended.
HOLD_S = 60.0
# How often the timer looks: the memory goes back within HOLD_S + _POLL_S.
_POLL_S = 1.0

# time.monotonic() at the end of the last render whose memory is still
# held, or None when nothing is held. Written by the render handler (the
# render job's thread in a window), read by the timer (the main thread).
_state = {"ended": None}


def held():
    """Whether the memory of an ended render is held for the next one."""
    return _state["ended"] is not None


def release():
    """Hand the library's kept memory back now (does not load the library)."""
    _state["ended"] = None
    native.release_memory()


@bpy.app.handlers.persistent
@never_raises("release the library's memory after the render")
def _on_render_end(*_args):
    if bpy.app.background:
        release()
    else:
        _state["ended"] = time.monotonic()


@never_raises("release the library's memory after the render", result=_POLL_S)
def _poll():
    ended = _state["ended"]
    if (ended is not None and time.monotonic() - ended >= HOLD_S
            and not bpy.app.is_job_running("RENDER")):
        release()
    return _POLL_S


_HANDLERS = (bpy.app.handlers.render_complete, bpy.app.handlers.render_cancel)


def register():
    for handlers in _HANDLERS:
        if _on_render_end not in handlers:
            handlers.append(_on_render_end)
    if not bpy.app.background and not bpy.app.timers.is_registered(_poll):
        bpy.app.timers.register(_poll, first_interval=_POLL_S, persistent=True)


def unregister():
    if bpy.app.timers.is_registered(_poll):
        bpy.app.timers.unregister(_poll)
    for handlers in _HANDLERS:
        while _on_render_end in handlers:
            handlers.remove(_on_render_end)
    release()
