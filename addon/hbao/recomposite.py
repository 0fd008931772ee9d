# SPDX-License-Identifier: GPL-2.0-or-later
"""Re-compositing a render after a node's settings changed: the AO follows
the new settings without rendering the scene again.

When a node's value changes after a render, Blender composites the existing
Render Results again but renders no scene (docs/blender-integration.md,
"Re-compositing"), so the helper's pass would keep the AO of the old
settings. When the changes since the last render are only in the nodes' AO
parameters (radius, directions, steps, blur, falloff, ...) and the AO cache
still holds the passes that render handed over, the add-on's timer (main
thread, no render or compositor job running) renders the helper scene
alone: its engine computes each node's AO from the cached passes, with no
save and no read of the Render Result, and the compositor then runs again.
A change that needs other passes (another view layer, the Normal link, the
guard band, back faces, a node added since) still needs a render, and the
node says so (render_record)."""
import bpy

from . import ao_cache, compat, helper_scene, node, render_record
from .planning import plan_node
from .report import log


class Request:
    """The refresh being rendered: `helper` computes for `main` at `frame`
    from the cached passes."""

    def __init__(self, main, helper, frame):
        self.main, self.helper, self.frame = main, helper, frame


_request = None
# Main scene name -> the record and settings whose refresh failed: not tried
# again (every tick) until one of them changes.
_failed = {}


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
    """(frame, what was compared) when `main`'s last render can be brought
    up to its nodes' current settings from the cached passes, else None.
    The helper's render must come out the size of those passes: its old
    pass is gone once it renders again, so a mismatch found then would
    leave the compositor without AO."""
    record = render_record.last_render(main.name)
    if record is None or helper.render.use_border:
        return None
    frame, signatures = record
    changed, current_signatures = False, []
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
        changed = True
    return (frame, (record, tuple(current_signatures))) if changed else None


def _render_helper(main, helper, frame):
    global _request
    _request = Request(main.name, helper.name, frame)
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
    only: the helper rendered alone from the cached passes, then the
    compositor run again. A node.hint_refreshers entry (main thread, no
    render running); returns whether it rendered. Without a window (`-b`)
    nothing composites again, so it does nothing unless told to
    (`in_background`, for the tests)."""
    if bpy.app.is_job_running("COMPOSITE"):
        return False
    if not bpy.context.window_manager.windows and not in_background:
        return False
    rendered = False
    for main in list(bpy.data.scenes):
        helper = helper_scene.helper_scene_of(main)
        if helper is None:
            continue
        due = _needs_refresh(main, helper)
        if due is None:
            continue
        frame, compared = due
        if _failed.get(main.name) == compared:
            continue
        try:
            if not _render_helper(main, helper, frame):
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
