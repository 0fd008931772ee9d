# SPDX-License-Identifier: GPL-2.0-or-later
"""Whether the Render Result shows the render the add-on handed over.
Blender keeps renders in the Render Result's slots (the Image Editor's slot
menu, J), saves and composites the slot it shows, and keeps what a
cancelled render (Esc) drew. So the hand-over (handover.py) must find the
render's own slot shown, and a refresh (recomposite.py) may bring only a
completed render up to date, and only while its slot is shown: an artist
who looked at another slot while a render ran got that slot's AO."""
import bpy

# {main scene name: the slot its running or last render writes}, set at the
# render's start, and {main scene name: whether that render completed}.
_written = {}
_completed = {}
# The scene of the render job running or last run: only its passes are the
# Render Result's (a sequencer strip's scene renders inside another's job).
_job_scene = None


def render_result_image():
    """Blender's Render Result image: by its usual name, else (renamed) the
    first of its type. Asked at every refresh tick: no walk over a file's
    images where the name finds it."""
    image = bpy.data.images.get("Render Result")
    if image is not None and image.type == "RENDER_RESULT":
        return image
    return next((image for image in bpy.data.images if image.type == "RENDER_RESULT"), None)


def shown_slot():
    """The Render Result's shown slot (0-based), or None."""
    slots = getattr(render_result_image(), "render_slots", None)
    return slots.active_index if slots is not None else None


def started(scene):
    """At a render job's start (any thread): it writes the slot shown then."""
    global _job_scene
    _job_scene = scene.name
    _written[scene.name] = shown_slot()
    _completed[scene.name] = False


def ended(scene, completed):
    _completed[scene.name] = completed


def other_slot_shown(scene):
    """(shown, written), numbered as the slot menu numbers them, where the
    Render Result shows another slot than `scene`'s render job writes; else
    None."""
    if scene.name != _job_scene:
        return None
    written, shown = _written.get(scene.name), shown_slot()
    if written is None or shown is None or written == shown:
        return None
    return shown + 1, written + 1


def _composited_again():
    """Whether Blender composites the Render Result again when a node
    changes: not with Render > Display Mode "Keep User Interface" (an
    exploratory run: the Render Result kept its composite)."""
    view = getattr(bpy.context.preferences, "view", None)
    return getattr(view, "render_display_type", "WINDOW") != "NONE"


def shows_last_render(scene_name):
    """Whether `scene_name`'s last render completed, its slot is shown and
    has been since (True where no render started since the add-on loaded:
    -b, tests), and Blender composites it again on a change. A node changed
    while another slot was shown made Blender composite that slot with the
    helper's one render, which then showed through the render's slot (an
    exploratory run): once seen shown, another slot ends the refreshes
    until the next completed render."""
    if not _composited_again():
        return False
    if scene_name not in _written:
        return True
    written, shown = _written[scene_name], shown_slot()
    if written is not None and shown is not None and written != shown:
        _completed[scene_name] = False
    return _completed.get(scene_name, False)
