# SPDX-License-Identifier: GPL-2.0-or-later
"""What the render hook said about each HBAO node (its status line) and the
nodes' hint lines, brought to the nodes. Nodes are written in the main
thread only: during an F12 render every render handler runs in the job's
thread, where nodes may not be written and no timer may be started, so a
timer, running while the add-on is enabled, shows what the render thread
posted (report.post_node_messages) once no render job runs, and keeps the
hint lines current; in `-b`, render_post shows it."""
import bpy

from . import compat, report, status_causes, ui_timers, writes
from .callback_guard import never_raises
from .node import hbao_nodes


def show_messages(node, messages, scene=None):
    """Show `messages` (report.NodeMessage) on `node`: the first one's short
    form, how many more there are, and every full text in the tooltip;
    with `scene` (the node's), only those that still hold (status_causes).
    Writes only what changed, since a write makes Blender composite again;
    returns whether it wrote."""
    if scene is not None:
        messages = status_causes.holding(messages, scene, node)
    status = messages[0].short if messages else ""
    if len(messages) > 1:
        status += f" (+{len(messages) - 1})"
    details = "\n".join(messages)
    record = report.record_of(messages)
    if (node.status, node.status_details, node.status_record) == (status, details, record):
        return False
    node.status, node.status_details, node.status_record = status, details, record
    return True


def kept_messages():
    """{scene name: {node name: [NodeMessage]}} of what the nodes of the file
    just opened kept of their status lines (report.messages_in), so that
    what the artist has fixed since is taken from them (drop_fixed_messages)."""
    kept = {}
    for scene in bpy.data.scenes:
        statuses = {node.name: report.messages_in(node.name, node.status_record)
                    for node in hbao_nodes(compat.compositor_tree(scene)) if node.status_record}
        if statuses:
            kept[scene.name] = statuses
    return kept


def drop_fixed_messages():
    """Take from the nodes' status lines what no longer holds since the
    last render (the artist turned Compositing on, relinked Depth): a
    hint_refreshers entry. Returns whether it wrote."""
    changed, seen = False, set()
    # the latest first: of scenes that share a tree (5.x), the node shows
    # the last render's messages (report._post)
    for scene_name, statuses in reversed(report.last_node_messages_of_scenes()):
        scene = bpy.data.scenes.get(scene_name)
        for node in hbao_nodes(compat.compositor_tree(scene) if scene else None):
            if node.name not in statuses or node.as_pointer() in seen:
                continue
            seen.add(node.as_pointer())
            try:
                changed |= show_messages(node, statuses[node.name], scene)
            except (AttributeError, RuntimeError):  # a linked, read-only tree
                continue
    return changed


# Called with no arguments by the timer, in the main thread when no render
# runs, to bring the nodes' hint lines (hint, hint_details) up to date;
# each returns whether it changed one (render_record.apply_hints;
# writes.stuck_line_changed), and drop_fixed_messages the status lines.
hint_refreshers = [writes.stuck_line_changed, drop_fixed_messages]


@never_raises("update the HBAO nodes' status lines")
def apply_node_messages():
    """Show what the hook last said about each node (main thread only: the
    render thread only posts it, report.post_node_messages). What Blender
    refuses to write for the moment waits for the next call (the timer's
    next tick); a node that cannot be written at all (a linked tree) keeps
    its line, and the console has the messages."""
    if not report.in_main_thread():
        return
    changed = False
    for scene_name, statuses in report.take_node_messages():
        scene = bpy.data.scenes.get(scene_name)
        for node in hbao_nodes(compat.compositor_tree(scene) if scene else None):
            if node.name not in statuses:
                continue
            try:
                written = show_messages(node, statuses[node.name], scene)
            except (AttributeError, RuntimeError) as error:
                if writes.writes_refused(error):
                    report.return_node_messages(scene_name, statuses)
                    break
                continue
            changed |= written
    if changed:
        _redraw_node_editors()


def _redraw_node_editors():
    for window in getattr(bpy.context.window_manager, "windows", ()):
        for area in window.screen.areas:
            if area.type == "NODE_EDITOR":
                area.tag_redraw()


# The timer asks writes.run_writing before it writes. It costs a
# dictionary check and, per HBAO node of a rendered scene, a comparison per
# tick.
_POLL_S = 0.25


@never_raises("update the HBAO nodes' status lines", result=_POLL_S)
def _poll_node_messages():
    if not bpy.app.is_job_running("RENDER"):
        if report.has_node_messages():
            writes.run_writing(apply_node_messages)
        if writes.run_writing(_refresh_all, ask=False)[1]:
            _redraw_node_editors()
    return _POLL_S


def _refresh_all():
    # (each on its own: one that fails at every tick stops no other)
    return any([_refresh(refresh) for refresh in hint_refreshers])


@never_raises("update an HBAO node's hint line", result=False)
def _refresh(refresh):
    return refresh()


@bpy.app.handlers.persistent
@never_raises("update the HBAO nodes' status lines")
def _on_render_done(*_args):
    apply_node_messages()  # `-b` and blocking renders: the main thread


_HANDLERS = (("render_post", _on_render_done), ("render_complete", _on_render_done),
             ("render_cancel", _on_render_done))


def register():
    for name, function in _HANDLERS:
        getattr(bpy.app.handlers, name).append(function)
    ui_timers.start(_poll_node_messages, _POLL_S)  # `-b`: render_post applies the messages


def unregister():
    ui_timers.stop(_poll_node_messages)
    for name, function in _HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        while function in handlers:
            handlers.remove(function)
