# SPDX-License-Identifier: GPL-2.0-or-later
"""Blender's calls into the add-on (application handlers, timers, the
message bus) never raise. Blender prints a traceback for an error there at
every call, and drops a timer that raised for the rest of the session: one
error in the half-second poll would have left the nodes' status lines and
the re-compositing dead until Blender restarted. Each such function is
wrapped once, where it is defined (`never_raises`): an error is logged once
per distinct text ("could not WHAT: ..."), and the function returns what it returns
when all is well (a timer: when to run again). No bpy import."""
import functools

from .report import log

# The failures logged so far, so that a timer's every tick or a handler's
# every frame does not repeat one.
_told = set()
# Ends every such line: the tests fail a Blender run whose output has it,
# unless the test injected the fault (tests/conftest.py).
FAILURE_MARK = "(an error in the HBAO add-on; it goes on)"


def never_raises(what, result=None):
    """Decorate a function Blender calls: an Exception in it is logged once
    as "could not `what`: ..." and `result` returned instead."""
    def decorate(function):
        @functools.wraps(function)
        def guarded(*args, **kwargs):
            try:
                return function(*args, **kwargs)
            except Exception as error:  # never break the artist's session
                text = f"could not {what}: {type(error).__name__}: {error} {FAILURE_MARK}"
                if text not in _told:
                    _told.add(text)
                    log(text)
                return result
        return guarded
    return decorate
