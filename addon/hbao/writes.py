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

import bpy

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
    """Whether Blender lets Python write data now; changes nothing."""
    try:
        bpy.ops.hbao.writes_probe()
    except RuntimeError as error:  # the poll's failure, or the refusal
        return not writes_refused(error)
    except AttributeError:  # the add-on being disabled: the probe is gone
        return True
    return True


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
    bpy.utils.unregister_class(HBAO_OT_writes_probe)
