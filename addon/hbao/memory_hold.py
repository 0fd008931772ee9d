# SPDX-License-Identifier: GPL-2.0-or-later
"""When the library's working memory goes back to the system after the
library has computed.

The library keeps a frame's buffers (about 24 bytes a pixel: 50 MB at
1080p, at most 512 MB) for its next call; hbao_release_memory() hands them
back. Released at each render's end, the next render's first AO faults
every page in again: 30-50 ms of a 1080p F12 render's AO on the project's
VMs (docs/speed.md, sessions 68 and 69). So, from each render's end and
each re-composite's AO (start_hold):

- In `-b` (and bpy) the memory goes back at once: an animation keeps it
  from frame to frame and releases it after its last, and the process
  usually ends soon after anyway.
- In a window, where the artist renders again after a look or a change, it
  is held for the add-on's preference Keep Memory After a Render (60 s
  unless set: preferences.py; without an entry in the preferences, as with
  `--addons`, 60 s), then released by a timer (render handlers run in
  the render job's thread, where no timer may be started); a render running
  then pushes the release back. Disabling the add-on releases it at once.
"""
import contextlib
import threading
import time

import bpy

from . import native, preferences, ui_timers
from .callback_guard import never_raises

# How often the timer looks: the memory goes back within the hold + _POLL_S.
_POLL_S = 1.0

# since: time.monotonic() when the hold of the memory began, or None when
# nothing is held; active: between register() and unregister(); in_use: how
# many uses of the library outside a render run now (in_use()), during
# which the timer releases nothing. Written by the render handler (the
# render job's thread in a window), the re-composite's worker and the timer
# (the main thread), under _lock: a use that ends as the timer releases
# either holds its memory after the release or keeps the timer from it.
_state = {"since": None, "active": False, "in_use": 0}
_lock = threading.Lock()


def held_since():
    """time.monotonic() when the memory now held began to be held, or None
    (nothing held)."""
    return _state["since"]


def held():
    """Whether the memory of the library's last use is held for the next."""
    return held_since() is not None


def release():
    """Hand the library's kept memory back now (does not load the library)."""
    with _lock:
        _state["since"] = None
    native.release_memory()


def start_hold(ended_uses=0):
    """The library has just computed (a render has ended, a re-composite's
    AO is done; any thread): in `-b`, or once the add-on is disabled (a
    re-composite's worker may finish after that), its memory goes back now;
    in a window it is held from now on (_poll). `ended_uses`: the in_use()
    blocks this ends, counted off in the same step."""
    with _lock:
        _state["in_use"] -= ended_uses
        hold = _state["active"] and not bpy.app.background
        _state["since"] = time.monotonic() if hold else None
    if not hold:
        native.release_memory()


def release_if_inactive():
    """After the engine's AO: where the add-on was disabled while the render
    ran (engine.py keeps the engine's class for that render, but the render
    handler that would release is gone), the memory goes back now; nothing
    else would release it before Blender quits."""
    with _lock:
        inactive = not _state["active"]
    if inactive:
        native.release_memory()


@contextlib.contextmanager
def in_use():
    """Around a use of the library outside a render (a re-composite's
    worker; any thread): the timer releases nothing while it runs (a render
    keeps it off by itself), and its end is start_hold's, in the same
    step as the count's, so that no release falls between them."""
    with _lock:
        _state["in_use"] += 1
    try:
        yield
    finally:
        start_hold(ended_uses=1)


@bpy.app.handlers.persistent
@never_raises("release the library's memory after the render")
def _on_render_end(*_args):
    start_hold()


@never_raises("release the library's memory after the render", result=_POLL_S)
def _poll():
    if bpy.app.is_job_running("RENDER"):
        return _POLL_S
    hold_s = preferences.keep_memory_seconds()  # (read here: the main thread)
    with _lock:
        since = _state["since"]
        due = (since is not None and _state["in_use"] == 0
               and time.monotonic() - since >= hold_s)
        if due:
            _state["since"] = None
    if due:
        native.release_memory()
    return _POLL_S


_HANDLERS = (bpy.app.handlers.render_complete, bpy.app.handlers.render_cancel)


def register():
    _state["active"] = True
    for handlers in _HANDLERS:
        if _on_render_end not in handlers:
            handlers.append(_on_render_end)
    ui_timers.start(_poll, _POLL_S)


def unregister():
    _state["active"] = False
    ui_timers.stop(_poll)
    for handlers in _HANDLERS:
        while _on_render_end in handlers:
            handlers.remove(_on_render_end)
    release()
