# SPDX-License-Identifier: GPL-2.0-or-later
"""Whether Blender lets Python change data now.

While any thread runs a read-only Python callback (a panel's or node's draw
or poll; Cycles' render in 3.4), Blender refuses every write to data and
every operator call from Python, in every thread: the switch is one flag for
the whole process, so the add-on's timers meet it by chance
(docs/blender-integration.md). Creating data-blocks and nodes
(`bpy.data.scenes.new`, `nodes.new`) is not refused, so a job that creates
and then writes would leave half-made data behind: it asks writes_allowed()
first (an operator call, which also brings the view layer up to date: only
when there is work), every creation is made whole or removed
(whole_or_removed), and a refusal met midway (the flag changed since)
leaves the rest of the job for a later call. Rarely the refusal does not
end until Blender restarts (refusal_watch.py): the add-on says so, and
run_writing then makes its timers' writes where Blender still allows
them."""
import contextlib

import bpy

from . import refusal_watch
from .callback_guard import never_raises
from .report import in_main_thread, log

# Each refusal's text, as 3.4 to 5.x word it ("can't" became "cannot" in 5.0).
_REFUSALS = ((AttributeError, "Writing to ID classes in this context is not allowed"),
             (RuntimeError, "modify blend data in this state"))


def writes_refused(error):
    """Whether `error` is Blender refusing a write or an operator for the
    moment (a retry on a later timer tick succeeds), rather than data that
    is read-only for good (a linked tree) or a bug."""
    return any(isinstance(error, kind) and text in str(error) for kind, text in _REFUSALS)


class HBAO_OT_writes_probe(bpy.types.Operator):
    """Never runs (its poll fails): calling it tells whether Blender
    refuses operators, and so writes, now"""
    bl_idname = "hbao.writes_probe"
    bl_label = "HBAO Writes Probe"
    bl_options = {"INTERNAL"}

    @classmethod
    def poll(cls, _context):
        return False

    def execute(self, _context):
        return {"CANCELLED"}


def writes_allowed():
    """Whether Blender lets Python write data now; changes nothing. A
    refusal that does not end is told to the artist (_watch_refusal)."""
    try:
        bpy.ops.hbao.writes_probe()
    except RuntimeError as error:  # the poll's failure, or the refusal
        allowed = not writes_refused(error)
    except AttributeError:  # the add-on being disabled: the probe is gone
        allowed = True
    else:
        allowed = True
    _watch_refusal(allowed)
    return allowed


_watch = refusal_watch.RefusalWatch()
_PYTHON_JOBS = ("RENDER", "RENDER_PREVIEW", "OBJECT_BAKE", "COMPOSITE")
POPUP_TITLE = "HBAO: Blender refuses changes"
STUCK_LINE = "Blender refuses changes"
_shown = {"popups": 0, "line": ("", "")}  # popups shown (the tests read it); the nodes' line


def python_job_running():
    """Whether a job runs that runs Python callbacks in another thread (a
    render, a bake, compositing): Blender's refusal of writes is then
    expected, and no write may be lifted past it."""
    for job in _PYTHON_JOBS:
        try:
            if bpy.app.is_job_running(job):
                return True
        except (TypeError, ValueError):  # a job type this Blender does not have
            pass
    return False


# A lifted write under way (run_writing): the probes it makes are not the
# session's answer (Blender allows them only inside it).
_lifting = [False]
_lifted_calls = []  # [action, its result, the exception it raised], the newest last
_LIFT_PROPERTY = "hbao_writes_lifted"


def run_writing(action, ask=True):
    """(True, action()) where Blender lets Python write now, else (False,
    None), for a timer's job that writes. ask=False, for a job that runs at
    every tick and meets a refusal by itself (writes only what changed):
    Blender is not asked first unless its refusal has been told, and
    action() just runs. Where the refusal is the kind
    that does not end (told: refusal_watch.py), in the main thread while no
    job that runs Python callbacks in another thread runs (no callback can
    then be reading), action runs inside a property's update callback,
    which Blender runs with writes allowed (docs/blender-integration.md,
    "Rarely the refusal does not end"): so the hook still follows the
    artist's nodes, and their status lines and the render's reports still
    reach them, until Blender restarts. What action raises goes on."""
    if (not ask and not _watch.told) or writes_allowed():
        return True, action()
    if not (_watch.told and in_main_thread() and not python_job_running()):
        return False, None
    call = [action, None, None]
    _lifted_calls.append(call)
    try:
        window_manager = bpy.context.window_manager
        # window-manager data is not refused; its update callback runs action
        setattr(window_manager, _LIFT_PROPERTY, not getattr(window_manager, _LIFT_PROPERTY))
    except (AttributeError, RuntimeError) as error:
        if not writes_refused(error):
            raise
        return False, None
    finally:
        _lifted_calls.remove(call)
    if call[2] is not None:
        raise call[2]
    return True, call[1]


def _run_lifted(_window_manager, _context):
    """The update callback: run_writing's newest call (inside it, writes
    are allowed, so a nested run_writing calls its action at once)."""
    if not _lifted_calls:
        return  # (the property set some other way)
    call = _lifted_calls[-1]
    _lifting[0] = True
    try:
        call[1] = call[0]()
    except Exception as error:  # raised again by run_writing
        call[2] = error
    finally:
        _lifting[0] = False


@never_raises("watch Blender's refusals of writes")
def _watch_refusal(allowed):
    """A refusal that does not end (refusal_watch.py) told to the artist,
    once: in the console, in a popup where a timer asked in a window (a
    popup is window-manager data, which Blender does not refuse), and on
    the HBAO nodes (stuck_line)."""
    if _lifting[0]:
        return
    seconds = _watch.note(allowed, not allowed and python_job_running())
    if seconds is None:
        return
    log(refusal_watch.stuck_text(seconds))
    if bpy.app.background or not in_main_thread() or bpy.context.window is None:
        return
    sentences = refusal_watch.stuck_sentences(seconds)

    def draw(menu, _context):
        for sentence in sentences:
            menu.layout.label(text=sentence)
    bpy.context.window_manager.popup_menu(draw, title=POPUP_TITLE, icon="ERROR")
    _shown["popups"] += 1


def stuck_line():
    """The HBAO nodes' line while the add-on has said that Blender's refusal
    does not end: (short, the full text), or ("", "")."""
    return (STUCK_LINE, refusal_watch.stuck_text(_watch.lasted)) if _watch.told else ("", "")


def stuck_line_changed():
    """For node_status.hint_refreshers: whether stuck_line() changed since the
    nodes were last redrawn for it."""
    line = stuck_line()
    changed, _shown["line"] = line != _shown["line"], line
    return changed


def told_stuck():
    """Whether the add-on has said that Blender's refusal does not end
    (since writes were last allowed), and how many popups it showed."""
    return _watch.told, _shown["popups"]


@contextlib.contextmanager
def whole_or_removed(remove):
    """Around the writes that make a data-block or node just created whole
    and findable (its key first): if one fails (refused, see above),
    remove() takes the half-made thing away again and the error goes on,
    so that no later sync meets data it does not know."""
    try:
        yield
    except BaseException:
        remove()
        raise


def register():
    bpy.utils.register_class(HBAO_OT_writes_probe)
    setattr(bpy.types.WindowManager, _LIFT_PROPERTY,
            bpy.props.BoolProperty(options={"HIDDEN", "SKIP_SAVE"}, update=_run_lifted))


def unregister():
    _watch.reset()
    _shown.update(popups=0, line=("", ""))
    if hasattr(bpy.types.WindowManager, _LIFT_PROPERTY):
        delattr(bpy.types.WindowManager, _LIFT_PROPERTY)
    bpy.utils.unregister_class(HBAO_OT_writes_probe)
