# SPDX-License-Identifier: GPL-2.0-or-later
"""How the render hook tells the artist what happened: one console prefix,
messages about a node that read well after Blender's "HBAO " report prefix
and carry a short form for the node's status line, and whether the caller
may change Blender data (only the main thread may)."""
import json
import sys
import threading

LOG_PREFIX = "HBAO:"

# scene name -> {node name: [NodeMessage]}: what the last planned frame said
# about each HBAO node of the scene, waiting for the main thread to show it on
# the nodes (node_status.apply_node_messages). Written by the render thread: one
# dict assignment, atomic under the GIL.
_pending_node_messages = {}
# The same, as last posted (not taken): an undo or redo brings back the
# statuses saved with its step, which these then replace again.
_last_node_messages = {}


# What the engine reported during a render, waiting for the main thread to
# add it to Blender's reports (render_reports.py): Blender 3.4 drops the
# reports of a scene that the compositor renders (the helper), so without
# this the Info editor never shows them. Appended by the render thread.
_pending_render_reports = []


def post_render_report(text):
    """Queue `text` for the Info editor and status bar. Any thread."""
    _pending_render_reports.append(text)


def has_render_reports():
    return bool(_pending_render_reports)


def take_render_reports():
    """The texts posted since the last call, oldest first."""
    taken = []
    while _pending_render_reports:
        taken.append(_pending_render_reports.pop(0))
    return taken


def log(message):
    """Print `message` to the console; never raises (a console that cannot
    show a name's characters, as a non-UTF-8 locale's under bpy, or a
    closed pipe, must not cost the render its AO)."""
    text = f"{LOG_PREFIX} {message}"
    try:
        print(text, flush=True)
    except UnicodeEncodeError:
        encoding = getattr(sys.stdout, "encoding", None) or "ascii"
        try:
            print(text.encode(encoding, "backslashreplace").decode(encoding), flush=True)
        except (OSError, ValueError, LookupError):  # LookupError: an unknown encoding
            pass
    except (OSError, ValueError):  # a closed or broken stdout
        pass


def in_main_thread():
    """F12 runs the render handlers in the render job's thread, where adding
    or removing data blocks and nodes is not allowed."""
    return threading.current_thread() is threading.main_thread()


class NodeMessage(str):
    """A message about one HBAO node. As a string it is the full text,
    'node "NAME": what happened; what it means', so that the engine's report
    reads 'HBAO node "HBAO": Depth is not linked; AO off'; `short` is the
    form that fits the node's status line. `cause`, where given, names
    what the message is about as plain values (status_causes.py checks
    whether it still holds once the artist changes something)."""

    def __new__(cls, node_name, detail, short, cause=None):
        message = super().__new__(cls, f'node "{node_name}": {detail}')
        message.node_name = node_name
        message.detail = detail
        message.short = short
        message.cause = cause
        return message


def record_of(messages):
    """`messages` (NodeMessages about one node) as text that a file keeps
    (the node's status_record), so that their causes can be checked again
    once the file is opened (messages_in)."""
    return json.dumps([[message.detail, message.short,
                        list(message.cause) if message.cause is not None else None]
                       for message in messages]) if messages else ""


def messages_in(node_name, record):
    """The NodeMessages about node `node_name` that record_of() wrote into
    `record`; none where it cannot be read (a file edited by hand)."""
    try:
        return [NodeMessage(node_name, str(detail), str(short),
                            tuple(cause) if isinstance(cause, list) else None)
                for detail, short, cause in json.loads(record or "[]")]
    except (ValueError, TypeError):
        return []


def post_node_messages(scene_name, node_names, messages):
    """Replace what the nodes `node_names` of scene `scene_name` show with
    `messages` (the NodeMessages among them; none clears a node's status).
    Any thread may call it."""
    statuses = {name: [] for name in node_names}
    for message in messages:
        if isinstance(message, NodeMessage):
            statuses.setdefault(message.node_name, []).append(message)
    _post(scene_name, statuses)


def _post(scene_name, statuses):
    _pending_node_messages[scene_name] = statuses
    # (the latest last: scenes that share a tree, 5.x, post in turn, and the
    # last render's messages must be shown last again)
    _last_node_messages.pop(scene_name, None)
    _last_node_messages[scene_name] = statuses


def add_node_messages(scene_name, messages):
    """Add `messages` (NodeMessages) to what post_node_messages last posted
    for scene `scene_name`: what the AO's computation found, after the plan
    was posted. Any thread may call it."""
    statuses = {name: list(found) for name, found in
                _last_node_messages.get(scene_name, {}).items()}
    for message in messages:
        statuses.setdefault(message.node_name, []).append(message)
    _post(scene_name, statuses)


def post_last_node_messages():
    """Post again what each scene's nodes were last told: an undo or redo
    restored older statuses."""
    for scene_name, statuses in list(_last_node_messages.items()):
        _pending_node_messages.setdefault(scene_name, statuses)


def last_node_messages(scene_name):
    """{node name: [NodeMessage]} last posted for scene `scene_name`."""
    return _last_node_messages.get(scene_name, {})


def last_node_messages_of_scenes():
    """(scene name, {node name: [NodeMessage]}) of every scene posted for,
    the latest last."""
    return list(_last_node_messages.items())


def forget_node_messages(kept=None):
    """Another file is open: its scenes were told only what its nodes kept,
    `kept` ({scene name: {node name: [NodeMessage]}}, messages_in)."""
    _last_node_messages.clear()
    _last_node_messages.update(kept or {})


def has_node_messages():
    """Whether messages wait for take_node_messages."""
    return bool(_pending_node_messages)


def take_node_messages():
    """[(scene name, {node name: [NodeMessage]})] posted since the last call."""
    taken = []
    for scene_name in list(_pending_node_messages):
        statuses = _pending_node_messages.pop(scene_name, None)
        if statuses is not None:
            taken.append((scene_name, statuses))
    return taken


def return_node_messages(scene_name, statuses):
    """Give back what take_node_messages gave for `scene_name` and could not
    be shown yet, unless a render posted newer messages meanwhile."""
    _pending_node_messages.setdefault(scene_name, statuses)


# Scene name -> [NodeMessage] of what the render hook changed for a render
# (a pass turned on), which that render's plan shows beside its own. The
# render thread and the main thread both note and take them.
_changes_for_render = {}
_changes_lock = threading.Lock()


def note_change(scene_name, message):
    """Keep `message` (a NodeMessage) for the plan of `scene_name`'s next
    render, which would otherwise replace it on the node. Any thread."""
    with _changes_lock:
        _changes_for_render.setdefault(scene_name, []).append(message)


def take_changes(scene_name):
    """The messages note_change() kept for `scene_name`, once."""
    with _changes_lock:
        return _changes_for_render.pop(scene_name, [])
