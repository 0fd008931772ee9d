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
leaves the rest of the job for a later call."""
import contextlib
import time

import bpy

from .report import log

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


# Rarely Blender's refusal does not end: two threads' callbacks that
# overlap out of order leave its flag set until Blender restarts
# (docs/blender-integration.md, "Rarely the refusal does not end"). Refused
# at every ask for STUCK_AFTER_S while no job that runs Python callbacks in
# another thread (a render, a bake) runs, the add-on says so, once, in the
# console and in a popup: every add-on's buttons and scripts fail then,
# which nothing else explains to the artist.
STUCK_AFTER_S = 5.0
# ... asked again at least this often meanwhile (the timers ask every 0.25 s
# while they have work): two refusals met by chance further apart are not one.
STUCK_ASKED_WITHIN_S = 1.0
_PYTHON_JOBS = ("RENDER", "RENDER_PREVIEW", "OBJECT_BAKE", "COMPOSITE")
STUCK_MESSAGE = ("Blender has refused every change from Python for {seconds:.0f} s with no render "
                 "running. It will until it restarts: a fault of Blender's (two of its callbacks "
                 "overlapped). Every add-on's buttons and scripts fail. Save the file and restart "
                 "Blender. Until then F12 still renders the HBAO pass, but the HBAO nodes' status "
                 "lines stay as they are.")
_refusal = {"since": None, "last": None, "told": False}


def _python_job_running():
    for job in _PYTHON_JOBS:
        try:
            if bpy.app.is_job_running(job):
                return True
        except (TypeError, ValueError):  # a job type this Blender does not have
            pass
    return False


def _watch_refusal(allowed):
    if allowed or _python_job_running():
        _refusal["since"] = None
        if allowed:
            _refusal["told"] = False
        return
    now = time.monotonic()
    if _refusal["since"] is None or now - _refusal["last"] > STUCK_ASKED_WITHIN_S:
        _refusal["since"] = now
    _refusal["last"] = now
    if not _refusal["told"] and now - _refusal["since"] >= STUCK_AFTER_S:
        _refusal["told"] = True
        _tell_stuck(STUCK_MESSAGE.format(seconds=now - _refusal["since"]))


def told_stuck():
    """Whether the add-on has said that Blender's refusal does not end
    (since writes were last allowed)."""
    return _refusal["told"]


def _tell_stuck(message):
    log(message)
    if bpy.app.background:
        return
    lines = [line if line.endswith(".") else line + "." for line in message.split(". ")]

    def draw(menu, _context):
        for line in lines:
            menu.layout.label(text=line)
    try:  # a popup is not refused (window-manager data)
        bpy.context.window_manager.popup_menu(draw, title="HBAO: Blender refuses changes",
                                              icon="ERROR")
    except Exception as error:  # the console has it
        log(f"could not show the popup: {type(error).__name__}: {error}")


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


def unregister():
    _refusal.update(since=None, last=None, told=False)
    bpy.utils.unregister_class(HBAO_OT_writes_probe)
