# SPDX-License-Identifier: GPL-2.0-or-later
"""When the hook is kept in sync: Blender's application handlers and a
timer, and the node's change callbacks.

Structural changes (helper scene, managed node, links) need the main
thread and must not happen inside node callbacks, so those only schedule a
sync. F12 runs the render handlers in the render job's thread: there they
copy plain settings only. `blender -b ... -f N` runs them in the main thread,
the only chance such a render has to build the hook."""
import bpy

from . import (compat, helper_lookup, helper_render_settings, helper_scene, node, node_place,
               node_status, older_blenders, pass_capture, pass_sources, planning, recomposite,
               render_slots, saved_switch, strip_cameras, unseen_occluders, window_scenes, writes)
from .callback_guard import never_raises
from .report import (NodeMessage, forget_node_messages, in_main_thread, log,
                     post_last_node_messages, post_node_messages, post_render_report)

_sync_scheduled = False
# How soon a sync that Blender refused (writes.py) runs again.
_REFUSED_RETRY_S = 0.25


def _refused(action, what):
    """Run `action`; whether Blender refused a write for the moment
    (writes.py). Any other error is logged as "could not `what`"."""
    try:
        action()
    except Exception as error:  # never break the user's session
        if writes.writes_refused(error):
            return True
        log(f"could not {what}: {error}")
    return False


def _sync_everything():
    """Every scene's nodes and hook; whether Blender refused a write. The
    windows first (window_scenes): a helper a window shows is not removed.
    Then the HBAO nodes that came with a group of their own (File > Append)
    get the shared one; not at a render's start: bpy 5.3 crashed when a
    node's group changed in render_pre."""
    return (_refused(window_scenes.leave_internal_scenes,
                     "move a window off the add-on's internal scene")
            or _refused(lambda: node.adopt_group_copies_of(bpy.data.scenes),
                        "give the HBAO nodes the add-on's group")
            or helper_scene.sync_all())


def _timer_sync():
    global _sync_scheduled
    if _sync_refused():
        return _REFUSED_RETRY_S  # still scheduled
    _sync_scheduled = False  # (also after an error: the next change schedules again)
    return None  # run once


@never_raises("update the HBAO hooks", result=False)
def _sync_refused():
    ran, refused = writes.run_writing(_sync_everything)
    return not ran or refused


def _sync_all_or_later():
    """sync_all() from a handler; what Blender refused waits for the timer."""
    if _sync_everything():
        log("Blender refused to update the HBAO hook just now; it is updated later "
            "(or at the render)")
        schedule_sync()


def schedule_sync():
    """Sync soon, from the main loop (node callbacks must not edit the tree)."""
    global _sync_scheduled
    if not _sync_scheduled and not bpy.app.background:
        _sync_scheduled = True
        bpy.app.timers.register(_timer_sync, first_interval=0.0)


@never_raises("move a window off the add-on's internal scene")
def _on_window_scene(*_args):
    """A window switched scenes: to an internal one, it goes back at once."""
    if window_scenes.shows_an_internal_scene():
        schedule_sync()


@bpy.app.handlers.persistent
@never_raises("restore the HBAO hook after an undo or redo")
def _on_undo_or_redo(*_args):
    """Undo and redo read the file back, and no depsgraph update follows:
    3.4 showed a helper scene after Scene > Delete, Ctrl+Z, Ctrl+Shift+Z, and
    rendered without AO after Scene > Delete, Ctrl+Z (the engine, asked
    for the helper's passes while the undo read the scenes back, found no
    main scene). The helpers' passes are asked for again, the nodes shown
    what they were last told, and the hook synced."""
    for helper in [scene for scene in bpy.data.scenes if helper_lookup.is_helper(scene)]:
        for layer in helper.view_layers:
            layer.update_render_passes()
    post_last_node_messages()
    schedule_sync()


@bpy.app.handlers.persistent
@never_raises("update the HBAO hooks of the file opened")
def _on_load_post(*_args):
    global _sync_scheduled
    _sync_scheduled = False  # opening a file removed the timer, if it waited
    forget_node_messages(node_status.kept_messages())
    window_scenes.watch(_on_window_scene)
    strip_cameras.forget_jobs()
    _sync_all_or_later()


@bpy.app.handlers.persistent
@never_raises("update the HBAO hooks before the save")
def _on_save_pre(*_args):
    # Background scripts get no timer: the hook is built at the latest here, so
    # that `blender -b file.blend -f N` finds it in the file.
    _sync_all_or_later()
    older_blenders.copy_node_settings()
    saved_switch.before_save()


@bpy.app.handlers.persistent
@never_raises("switch the HBAO scenes on again after the save")
def _on_save_post(*_args):
    saved_switch.after_save()


@bpy.app.handlers.persistent
@never_raises("prepare the HBAO hook for the render job")
def _on_render_init(scene, *_args):
    """Once a render job, in the console and the Info editor: why the HBAO
    nodes that get no AO where they lie get none (node_place.py), and that
    Render Single Layer turns the AO off (on the nodes' status lines too);
    then as every frame."""
    strip_cameras.job_started(scene)
    if not window_scenes.is_internal(scene):
        render_slots.started(scene)
    if not helper_lookup.is_helper(scene):
        tree = compat.compositor_tree(scene)
        messages = list(_misplaced_messages(scene))
        messages += [(text, f"HBAO {text}")
                     for text in unseen_occluders.render_messages(scene, tree)]
        nodes = node.hbao_nodes(tree)
        off = helper_render_settings.ao_off_by(scene) if nodes else None
        if off is not None:
            detail, short, cause = off
            statuses = [NodeMessage(n.name, detail, short, cause) for n in nodes]
            post_node_messages(scene.name, [n.name for n in nodes], statuses)
            messages.append((detail, f"HBAO: {detail}"))
        for text, report_text in messages:
            log(text)
            if not bpy.app.background:  # `-b`: the console has it
                post_render_report(report_text)
    _on_render_pre(scene)


@never_raises("prepare the render's HBAO messages", result=())
def _misplaced_messages(scene):
    """(the console's text, the report's) of each HBAO node that gets no AO
    where it lies: a node's report reads "HBAO node ...". Guarded on its
    own: a failure here costs no status line of the render's."""
    return [(text, f"HBAO {text}") for text in node_place.render_messages(scene)]


@bpy.app.handlers.persistent
@never_raises("prepare the HBAO hook for the render")
def _on_render_pre(scene, *_args):
    if helper_lookup.is_helper(scene):
        return
    recomposite.cancel_all()  # a render of any scene needs the cores
    tree = compat.compositor_tree(scene)
    if not node.hbao_nodes(tree):
        _unhook_before_render(scene)
        return
    try:
        if in_main_thread():
            helper_scene.sync(scene, rendering=True)
        else:
            pass_sources.enable_needed_passes(scene, tree)
        # The helper may serve several scenes (5.x): its engine computes for this one.
        helper_scene.record_rendering(scene)
    except Exception as error:
        log(f"could not prepare the HBAO hook of {scene.name!r}: {error}")
    planning.watch_passes(scene)


@bpy.app.handlers.persistent
@never_raises("prepare the HBAO hook for the frame")
def _on_frame_render_pre(scene, *_args):
    strip_cameras.frame_started(scene)
    _on_render_pre(scene)


def _unhook_before_render(scene):
    """The last HBAO node deleted since the last sync (a script in `blender
    -b`, where no timer syncs): the hook goes now where Blender allows it;
    in F12's render thread, where it cannot, the helper still renders for
    this scene (its engine computes no AO, and says nothing)."""
    if helper_lookup.helper_scene_of(scene) is None:
        return
    try:
        if in_main_thread():
            helper_scene.sync(scene)
        else:
            helper_scene.record_rendering(scene)
    except Exception as error:
        log(f"could not remove the HBAO hook of {scene.name!r}: {error}")


@bpy.app.handlers.persistent
@never_raises("close the render's HBAO records")
def _on_render_complete(scene, *_args):
    _on_render_end(scene, True)


@bpy.app.handlers.persistent
@never_raises("close the render's HBAO records")
def _on_render_cancel(scene, *_args):
    _on_render_end(scene, False)


def _on_render_end(scene, completed):
    strip_cameras.job_ended(scene)
    if helper_lookup.is_helper(scene):
        return
    pass_capture.forget(scene)
    render_slots.ended(scene, completed)
    helper_scene.record_render_end(scene)
    # (`-b`, scripts) the extra scenes the render's start kept go, once the
    # outermost job has ended: a sequencer strip's scene renders in a job of
    # its own inside the sequencer scene's, whose next frame would crash
    if in_main_thread() and not strip_cameras.jobs_running():
        helper_scene.sync_all()


@bpy.app.handlers.persistent
@never_raises("follow an edit for the HBAO hook")
def _on_depsgraph_update_post(scene, *_args):
    if not in_main_thread():
        return
    if window_scenes.is_internal(scene):
        if window_scenes.shown_in_a_window(scene):  # (a scene was deleted)
            schedule_sync()
        return
    tree = compat.compositor_tree(scene)
    # (a sequencer's strips may show an HBAO scene through a camera the
    # helper must link: view_cameras.render_cameras)
    if node.hbao_nodes(tree) or helper_lookup.managed_node(tree) is not None \
            or getattr(scene, "sequence_editor", None) is not None:
        schedule_sync()


_HANDLERS = (
    (bpy.app.handlers.load_post, _on_load_post),
    (bpy.app.handlers.save_pre, _on_save_pre),
    (bpy.app.handlers.save_post, _on_save_post),
    (bpy.app.handlers.render_init, _on_render_init),
    (bpy.app.handlers.render_pre, _on_frame_render_pre),
    (bpy.app.handlers.render_complete, _on_render_complete),
    (bpy.app.handlers.render_cancel, _on_render_cancel),
    (bpy.app.handlers.depsgraph_update_post, _on_depsgraph_update_post),
    (bpy.app.handlers.undo_post, _on_undo_or_redo),
    (bpy.app.handlers.redo_post, _on_undo_or_redo),
) + (((bpy.app.handlers.save_post_fail, _on_save_post),)
     if hasattr(bpy.app.handlers, "save_post_fail") else ())  # (4.2+)


def register():
    for handlers, function in _HANDLERS:
        if function not in handlers:
            handlers.append(function)
    if schedule_sync not in node.changed_callbacks:
        node.changed_callbacks.append(schedule_sync)
    window_scenes.watch(_on_window_scene)
    # Enabled in a session (Preferences, after a disable, which let go of
    # the hooks: hook_release.py): register() cannot read the file, and no
    # depsgraph update need follow, so F12 rendered without AO until an
    # edit. The hooks are made again at the first tick.
    schedule_sync()


def unregister():
    global _sync_scheduled
    if bpy.app.timers.is_registered(_timer_sync):
        bpy.app.timers.unregister(_timer_sync)
    _sync_scheduled = False
    window_scenes.unwatch()
    if schedule_sync in node.changed_callbacks:
        node.changed_callbacks.remove(schedule_sync)
    for handlers, function in _HANDLERS:
        if function in handlers:
            handlers.remove(function)
