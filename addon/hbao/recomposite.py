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

from . import ao_cache, compat, helper_scene, layer_passes, node, render_record
from .planning import plan_node
from .report import log


class Request:
    """The refresh being rendered: `helper` computes for `main` at `frame`
    from the cached passes, where the changed nodes' AO already is (computed
    in `ao_seconds`)."""

    def __init__(self, main, helper, frame, ao_seconds=0.0):
        self.main, self.helper, self.frame = main, helper, frame
        self.ao_seconds = ao_seconds


_request = None
# Main scene name -> the record and settings whose refresh failed: not tried
# again (every tick) until one of them changes.
_failed = {}


class _Computation:
    """The AO of a refresh's changed jobs, computed in a worker thread from
    the kept passes: {cache key: (AOInputs, ao)}, or the error."""

    def __init__(self, compared, work):
        self.compared = compared
        self.results, self.error, self.seconds = {}, None, 0.0
        self.thread = threading.Thread(target=self._run, args=(work,), daemon=True)
        self.thread.start()

    def _run(self, work):
        start = time.perf_counter()
        try:
            for key, job, inputs, extra in work:
                depth, normal = inputs.arrays[0], inputs.arrays[1]
                self.results[key] = (inputs, layer_passes.compute(job, depth, normal,
                                                                  inputs.camera, extra))
        except Exception as error:  # reported by the main thread
            self.error = error
        self.seconds = time.perf_counter() - start

    def done(self):
        return not self.thread.is_alive()


# Main scene name -> its refresh's computation, while it runs or waits.
_computing = {}


def request_for(helper):
    """The refresh whose render is rendering `helper` now, or None."""
    request = _request
    return request if request is not None and request.helper == helper.name else None


def _render_size(scene):
    """(height, width) of a render of `scene` without a border, as Blender
    sizes it (resolution times the percentage, rounded down)."""
    settings = scene.render
    percent = settings.resolution_percentage
    return (settings.resolution_y * percent // 100, settings.resolution_x * percent // 100)


def _needs_refresh(main, helper):
    """(frame, what was compared, [changed Job]) when `main`'s last render
    can be brought up to its nodes' current settings from the cached
    passes, else None.
    The helper's render must come out the size of those passes: its old
    pass is gone once it renders again, so a mismatch found then would
    leave the compositor without AO."""
    record = render_record.last_render(main.name)
    if record is None or helper.render.use_border:
        return None
    frame, signatures = record
    changed, current_signatures = [], []
    for hbao_node in node.hbao_nodes(compat.compositor_tree(main)):
        if hbao_node.mute or not any(output.is_linked for output in hbao_node.outputs):
            continue  # the compositor shows those at once
        if hbao_node.name not in signatures:
            return None  # added since the render
        try:
            job = plan_node(hbao_node, main, frame, [])
        except Exception:  # the next render says what is wrong
            return None
        if job is not None:
            kept = ao_cache.last_render.entry((main.name, job.pass_name))
            if kept is None or kept[0].arrays[0].shape != _render_size(helper):
                return None
        recorded, current = signatures[hbao_node.name], render_record.signature_of(job)
        current_signatures.append((hbao_node.name, current))
        if current == recorded:
            continue
        if current is not None and not render_record.same_passes(recorded, current):
            return None
        changed.append(job)
    return (frame, (record, tuple(current_signatures)), changed) if changed else None


def _work(main, jobs):
    """(cache key, job, AOInputs, ExtraPasses) of each job that computes,
    its passes those the last render kept."""
    work = []
    for job in jobs:
        if job is None:
            continue
        key = (main.name, job.pass_name)
        kept = ao_cache.last_render.entry(key)[0]
        inputs = ao_cache.AOInputs(job.params, kept.camera, kept.settings, kept.arrays)
        work.append((key, job, inputs, layer_passes.extra_of(kept.settings, kept.arrays)))
    return work


def _render_helper(main, helper, frame, ao_seconds):
    global _request
    _request = Request(main.name, helper.name, frame, ao_seconds)
    try:
        windows = bpy.context.window_manager.windows
        override = {"window": windows[0]} if windows else {}
        with bpy.context.temp_override(scene=main, **override):
            result = bpy.ops.render.render(scene=helper.name)
    finally:
        _request = None
    return "FINISHED" in result


def refresh_changed(in_background=False):
    """For each scene whose nodes changed since its render in AO parameters
    only: the changed AO computed in a worker thread from the cached
    passes (a first call starts it, a later one finds it done), then the
    helper rendered alone and the compositor run again. A
    node.hint_refreshers entry (main thread, no render running); returns
    whether it rendered. Without a window (`-b`) nothing composites again,
    so it does nothing unless told to (`in_background`, for the tests and
    the benchmark: then it waits for the computation)."""
    if bpy.app.is_job_running("COMPOSITE"):
        return False
    if not bpy.context.window_manager.windows and not in_background:
        return False
    rendered = False
    for main in list(bpy.data.scenes):
        helper = helper_scene.helper_scene_of(main)
        due = _needs_refresh(main, helper) if helper is not None else None
        if due is None:
            _computing.pop(main.name, None)  # a running one's result is dropped
            continue
        frame, compared, changed = due
        if _failed.get(main.name) == compared:
            continue
        try:
            computation = _computing.get(main.name)
            if computation is None or computation.compared != compared:
                # Started now; settings that change while it runs start another.
                computation = _computing[main.name] = _Computation(compared,
                                                                   _work(main, changed))
            if in_background:
                computation.thread.join()
            if not computation.done():
                continue
            del _computing[main.name]
            if computation.error is not None:
                raise computation.error
            for key, entry in computation.results.items():
                ao_cache.last_render.put(key, *entry)
            if not _render_helper(main, helper, frame, computation.seconds):
                raise RuntimeError("the helper scene's render did not finish")
            _composite_again(main)
        except Exception as error:  # the node keeps saying "render to update"
            _failed[main.name] = compared
            log(f"could not bring the AO of {main.name!r} up to its node settings: {error}")
            continue
        _failed.pop(main.name, None)
        rendered = True
    return rendered


def _composite_again(main):
    """A value written to a socket of `main`'s tree (the same value):
    Blender composites the tree again (in the editors that show it), now
    with the new AO. Neither the tree's update_tag() nor a write to a node
    property does."""
    for hbao_node in node.hbao_nodes(compat.compositor_tree(main)):
        for socket in hbao_node.inputs:
            if socket.enabled and isinstance(getattr(socket, "default_value", None),
                                             (int, float)):
                socket.default_value = socket.default_value
                return


def register():
    # Before render_record's hint refresher, which then finds the record up
    # to date and clears the nodes' hints.
    if refresh_changed not in node.hint_refreshers:
        node.hint_refreshers.insert(0, refresh_changed)


def unregister():
    if refresh_changed in node.hint_refreshers:
        node.hint_refreshers.remove(refresh_changed)
