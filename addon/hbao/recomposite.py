# SPDX-License-Identifier: GPL-2.0-or-later
"""Re-compositing a render after a node's settings changed: the AO follows
the new settings without rendering the scene again.

When a node's value changes after a render, Blender composites the existing
Render Results again but renders no scene (docs/blender-integration.md,
"Re-compositing"), so the helper's pass would keep the AO of the old
settings. When the changes since the last render are only in the nodes' AO
parameters (radius, directions, steps, blur, falloff, ...) and the AO cache
still holds the passes that render handed over, the add-on's timer (main
thread, no render or compositor job running) computes each changed node's
AO from the cached passes in a worker thread (the UI stays responsive while
a value is dragged), then renders the helper scene alone, whose engine
finds that AO in the cache (no save and no read of the Render Result), and
makes the compositor run again.
A change that needs other passes (another view layer, the Normal link, the
guard band, back faces, a node added since) still needs a render, and the
node says so (render_record)."""
import threading
import time

import bpy

from . import (ao_cache, composite_trigger, handler_hold, helper_scene, layer_passes, memory_hold,
               native, node_status, refresh_due, render_record, writes)
from .callback_guard import never_raises
from .report import log


class Request:
    """The refresh being rendered: `helper` computes for `main` at `frame`
    from the cached passes, where the changed nodes' AO already is (computed
    in `ao_seconds`). The engine sets `completed` once every pass is
    computed: a failed refresh still finishes rendering, with AO 1."""

    def __init__(self, main, helper, frame, ao_seconds=0.0):
        self.main, self.helper, self.frame = main, helper, frame
        self.ao_seconds = ao_seconds
        self.completed = False


_request = None


# Main scene name -> the refresh_due.Due whose refresh failed: not tried again (every
# tick) until the settings change or the scene renders again.
_failed = {}


class _Computation:
    """The AO of a refresh's changed jobs, computed in a worker thread from
    the kept passes: {cache key: (AOInputs, ao, notes)}, or the error. Once
    `cancelled` (cancel_all()), the worker starts no further job."""

    def __init__(self, due, work):
        self.due = due
        self.results, self.error, self.seconds = {}, None, 0.0
        self.cancelled = False
        self.thread = threading.Thread(target=self._run, args=(work,), daemon=True)
        self.thread.start()

    def _run(self, work):
        start = time.perf_counter()
        # the library's memory held from the end (its AO may be dropped unrendered:
        # a failure, or a change that needs a render)
        with memory_hold.in_use():
            try:
                for key, job, inputs, extra in work:
                    if self.cancelled:
                        break
                    depth, normal = inputs.arrays[0], inputs.arrays[1]
                    ao = layer_passes.compute(job, depth, normal, inputs.camera, extra)
                    self.results[key] = (inputs, ao, native.last_notes())  # (this thread's)
            except Exception as error:  # reported by the main thread
                self.error = error
        self.seconds = time.perf_counter() - start

    def done(self):
        return not self.thread.is_alive()


# Main scene name -> its refresh's computation: one at a time per scene; a
# change while it runs waits for it, and then starts another.
_computing = {}


def cancel_all():
    """A render began (any thread): every refresh's worker stops after the job it is
    computing rather than compete with the render for the cores. A render of the worker's
    own scene brings its AO up to date, which drops the refresh; otherwise (another scene,
    or the render cancelled) the next tick's refresh goes on from what the worker computed
    (the helper's engine computes the rest from the kept passes)."""
    for computation in list(_computing.values()):
        computation.cancelled = True


def request_for(helper):
    """The refresh whose render is rendering `helper` now, or None."""
    request = _request
    return request if request is not None and request.helper == helper.name else None


def _work(main, jobs):
    """(cache key, job, AOInputs, ExtraPasses) of each job that computes,
    its passes those the last render kept."""
    work = []
    for job in jobs:
        if job is None:
            continue
        key = ao_cache.key(main.name, job.pass_name)
        kept = ao_cache.last_render.entry(key)[0]
        inputs = ao_cache.AOInputs(job.params, kept.camera, kept.settings, kept.arrays)
        work.append((key, job, inputs, layer_passes.extra_of(kept.settings, kept.arrays)))
    return work


def _render_helper(main, helper, frame, ao_seconds):
    """Whether the helper rendered every pass for `main` (Request.completed). No render or
    frame change handler but the add-on's own runs for this render (handler_hold.py)."""
    global _request
    request = _request = Request(main.name, helper.name, frame, ao_seconds)
    try:
        windows = bpy.context.window_manager.windows
        override = {"window": windows[0]} if windows else {}
        with bpy.context.temp_override(scene=main, **override), handler_hold.held_back():
            bpy.ops.render.render(scene=helper.name)
    finally:
        _request = None
    return request.completed


def _install(computation):
    """Put a finished computation's AO in the cache; False when the cache
    no longer holds the arrays it was computed from (a render since)."""
    for key, (inputs, _ao, _notes) in computation.results.items():
        entry = ao_cache.last_render.entry(key)
        if entry is None or entry[0].arrays is not inputs.arrays:
            return False
    for key, (inputs, ao, notes) in computation.results.items():
        ao_cache.last_render.put(key, inputs, ao, notes)
    return True


def _refresh(main, helper, due, in_background):
    """One tick of `main`'s refresh: start its computation, or, once it is
    done, render the helper and composite again. Returns whether it
    rendered; raises when the refresh failed."""
    computation = _computing.get(main.name)
    if computation is None:
        computation = _computing[main.name] = _Computation(due, _work(main, due.changed))
    if in_background:
        computation.thread.join()
    if not computation.done():
        return False
    del _computing[main.name]
    if not computation.due.same_as(due):
        return False  # the settings or the render changed meanwhile: the next tick starts over
    if computation.error is not None:
        raise computation.error
    if not _install(computation):
        return False
    record = render_record.last_render(main.name)
    try:
        rendered = _render_helper(main, helper, due.record[0], computation.seconds)
    except RuntimeError as error:
        if not writes.writes_refused(error):
            raise
        _computing[main.name] = computation  # the next tick renders with its AO
        return False
    if not rendered:
        # The engine recorded the new settings before it failed: the node
        # says again that its AO is not up to date.
        render_record.put_back(main.name, record)
        raise RuntimeError("the helper scene's render did not compute the AO (see the Info "
                           "editor)")
    composite_trigger.composite_again(main)
    return True


def refresh_changed(in_background=False):
    """For each scene whose nodes changed since its render in AO parameters
    only: the changed AO computed in a worker thread from the cached
    passes (a first call starts it, a later one finds it done), then the
    helper rendered alone and the compositor run again. A
    node_status.hint_refreshers entry (main thread, no render running); returns
    whether it rendered. Without a window (`-b`) nothing composites again,
    so it does nothing unless told to (`in_background`, for the tests and
    the benchmark: then it waits for the computation)."""
    if bpy.app.is_job_running("COMPOSITE"):
        return False
    if not bpy.context.window_manager.windows and not in_background:
        return False
    composite_trigger.retry_refused()
    rendered, helpers_rendered = False, set()
    for main in list(bpy.data.scenes):
        has_record = render_record.last_render(main.name) is not None  # (else: nothing to do)
        helper = helper_scene.helper_scene_of(main) if has_record else None
        due = refresh_due.due_for(main, helper) if helper is not None else None
        if due is None:
            computation = _computing.get(main.name)
            if computation is not None and computation.done():
                del _computing[main.name]  # its result is of no use now
            continue
        # A helper that serves several scenes (5.x) holds one scene's AO at a
        # time: the others wait for the next tick, after this composite.
        if helper.name in helpers_rendered or due.same_as(_failed.get(main.name)):
            continue
        try:
            if not _refresh(main, helper, due, in_background):
                continue
        except Exception as error:  # the node keeps saying "render to update"
            _failed[main.name] = due
            log(f"could not bring the AO of {main.name!r} up to its node settings: {error}")
            continue
        _failed.pop(main.name, None)
        helpers_rendered.add(helper.name)
        rendered = True
    return rendered


@bpy.app.handlers.persistent
@never_raises("forget the last renders' passes")
def _on_load_pre(*_args):
    # What the last renders kept belongs to the file being closed (names recur).
    _computing.clear()
    _failed.clear()
    composite_trigger.forget()
    ao_cache.last_render.clear()
    render_record.forget()


def register():
    # Before render_record's hint refresher, which then finds the record up
    # to date and clears the nodes' hints.
    if refresh_changed not in node_status.hint_refreshers:
        node_status.hint_refreshers.insert(0, refresh_changed)
    if _on_load_pre not in bpy.app.handlers.load_pre:
        bpy.app.handlers.load_pre.append(_on_load_pre)


def unregister():
    if _on_load_pre in bpy.app.handlers.load_pre:
        bpy.app.handlers.load_pre.remove(_on_load_pre)
    if refresh_changed in node_status.hint_refreshers:
        node_status.hint_refreshers.remove(refresh_changed)
    _computing.clear()
    _failed.clear()
    composite_trigger.forget()
