# SPDX-License-Identifier: GPL-2.0-or-later
"""How the scripts that drive a real Blender window from timers end it: a
timer whose step raises, a script's own timeout and a quit that does not
happen all end Blender at once with a message, so that the test fails
within seconds with that message instead of waiting for its own timeout
on a Blender left idle.

  sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
  import timer_guard
"""
import os
import sys
import time
import traceback

import bpy
from hbao import writes  # the scripts run with the add-on enabled

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))), "scripts"))
from bpy_blender import remove_session_temp_folder  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from stuck_marks import WITH_WRITES_ALLOWED  # noqa: E402


def give_up(message):
    """Ends Blender at once with exit status 3, after printing message: a
    script's timeout. bpy.ops.wm.quit_blender() only schedules the quit,
    which a render still running can hold up; the test then waited for its
    own timeout and left the process behind."""
    print(message, flush=True)
    os._exit(3)


# How soon a step or a quit that Blender refused is tried again, and how
# often in a row before the script gives up (40 s).
REFUSED_RETRY_S = 0.25
REFUSED_RETRIES = 160


# Blender refuses writes and operators in every thread while any thread
# runs a read-only callback (a draw, Cycles' render); the flag it keeps for
# that is one for the whole process, which a callback saves and restores
# around itself. Rarely (1 in some 10 runs of test_ui.py under load; CI
# runs of sessions 15, 16, 39 and 48) the refusal then never ended: a fresh
# F12 was refused for 240 s on an idle Blender. Two threads' callbacks that
# overlap out of order leave the flag set (docs/blender-integration.md,
# "Rarely the refusal does not end"; ui_stuck_writes.py makes it happen).
# A refusal that lasts REDRAW_AFTER_S asks every window for a redraw (as a
# mouse move would), says so, and says when Blender accepts again.
REDRAW_AFTER_S = 5.0
_refused = {}  # label -> [first refusal time, refusals, last redraw time]


def _note_refusal(label, error):
    now = time.monotonic()
    entry = _refused.setdefault(label, [now, 0, now])
    entry[1] += 1
    if entry[1] == 1:
        print(f"{label}: Blender refused it for now:", error, flush=True)
    if now - entry[2] >= REDRAW_AFTER_S:
        entry[2] = now
        print(f"{label}: still refused after {now - entry[0]:.1f} s ({entry[1]} times; "
              f"a render job running: {bpy.app.is_job_running('RENDER')}): asking every "
              "window for a redraw", flush=True)
        for window in bpy.context.window_manager.windows:
            for area in window.screen.areas:
                area.tag_redraw()


def _note_accepted(label):
    entry = _refused.pop(label, None)
    if entry is not None and entry[1] > 1:
        print(f"{label}: accepted after {time.monotonic() - entry[0]:.1f} s of refusals "
              f"({entry[1]} times)", flush=True)


# A refusal that lasts STUCK_AFTER_S while no job that runs Python
# callbacks in another thread runs (no render: writes.python_job_running)
# is that stuck state. A script's steps stand for the artist's edits and
# key presses, which Python's refusal does not reach: such a step, or its
# operator, then runs with writes allowed (with_writes_allowed), after a
# line that says so (stuck_marks.py; the test summary lists such runs).
# CI met the state by chance in a UI test's Ctrl+Z (session 57: refused
# for 57 s, the test failed).
STUCK_AFTER_S = 10.0


def _stuck(label, after_s):
    """Whether `label` has been refused for after_s with no such job."""
    entry = _refused.get(label)
    return (entry is not None and time.monotonic() - entry[0] >= after_s
            and not writes.python_job_running())


def _allowed_after_refusals(label, function):
    print(f"{label}: refused for {time.monotonic() - _refused[label][0]:.1f} s; "
          f"{WITH_WRITES_ALLOWED}", flush=True)
    return with_writes_allowed(function)


def refused_for_now(operation, label, stuck_after_s=STUCK_AFTER_S):
    """Calls operation() (an operator); True, after saying so, when Blender
    refused it for the moment: while another thread runs a read-only
    callback (a draw, Cycles' render) it refuses operators in every thread,
    the timers' too (a CI run, session 16: the quit after an F12 render).
    Refused for stuck_after_s, it runs with writes allowed (above)."""
    try:
        operation()
    except RuntimeError as error:
        if not writes.writes_refused(error):
            raise
        _note_refusal(label, error)
        if not _stuck(label, stuck_after_s):
            return True
        print(f"{label}:", _allowed_after_refusals(label, operation), flush=True)
    _note_accepted(label)
    return False


def guarded_timer(step, first_interval, persistent=False, label="STEP"):
    """bpy.app.timers.register(step), except that an exception in step ends
    Blender (exit status 1, the traceback printed) instead of unregistering
    the timer silently and leaving Blender idle until the test's timeout.
    A step that Blender refused a write or an operator runs again
    REFUSED_RETRY_S later, up to REFUSED_RETRIES times in a row, and with
    writes allowed once refused for STUCK_AFTER_S (above): a step changes
    its state only after its writes and operators, or makes them once
    (f12_job.F12Job asks for its render again itself). A `persistent`
    timer goes on after a file is opened. Timers that run at once keep
    their refusals apart by their `label` (STEP for most)."""
    refusals = [0]

    def guarded():
        try:
            if _stuck(label, STUCK_AFTER_S):
                interval = _allowed_after_refusals(label, step)
            else:
                interval = step()
            refusals[0] = 0
            _note_accepted(label)
            return interval
        except Exception as error:
            if writes.writes_refused(error) and refusals[0] < REFUSED_RETRIES:
                refusals[0] += 1
                _note_refusal(label, error)
                return REFUSED_RETRY_S
            print("SCRIPT ERROR in the timer:", traceback.format_exc(), sep="\n", flush=True)
            os._exit(1)
    bpy.app.timers.register(guarded, first_interval=first_interval, persistent=persistent)


def end_now(status=0):
    """Ends Blender at once with `status`, its session's temporary folder
    removed as its own exit removes it: for a script after which the event
    loop must not run again. Blender 3.4 crashes (in its own code, without
    this add-on too) on the event loop's next pass after
    screen.screen_full_area ran from a timer, and quit_blender() only
    schedules the quit, which a draw in another thread can hold up for a
    pass or more (the crash then blamed the last operator, the preview's
    toggle: /tmp/blender.crash.txt, a test_viewport flake)."""
    sys.stdout.flush()
    sys.stderr.flush()
    remove_session_temp_folder()
    os._exit(status)


QUIT_GRACE_S = 30.0

# How long a refused quit is asked for again before it goes through
# with_writes_allowed instead.
QUIT_DIRECTLY_S = 2.0

_allowed_calls = []  # the calls under way: [function, its result, the exception it raised]


def _run_allowed(_window_manager, _context):
    """The update callback: with_writes_allowed's newest call only (a
    nested call's update would run the outer call again)."""
    if not _allowed_calls:
        return
    call = _allowed_calls[-1]
    try:
        call[1] = call[0]()
    except Exception as error:  # raised again by with_writes_allowed
        call[2] = error


bpy.types.WindowManager.timer_guard_writes_allowed = bpy.props.BoolProperty(update=_run_allowed)


def with_writes_allowed(function):
    """function()'s result, called where Blender allows writes and
    operators even while it refuses them elsewhere: a window-manager
    property's update callback (bpy.props' update callbacks lift the
    refusal around themselves, and window-manager data is exempt from
    it). Checked under Xvfb with Blender 3.4 from a header's draw, where a
    direct quit is refused, and in the stuck state of ui_stuck_writes.py."""
    call = [function, None, None]
    _allowed_calls.append(call)
    try:
        window_manager = bpy.context.window_manager
        window_manager.timer_guard_writes_allowed = \
            not window_manager.timer_guard_writes_allowed
    finally:
        _allowed_calls.remove(call)
    if call[2] is not None:
        raise call[2]
    return call[1]


def quit_blender():
    """bpy.ops.wm.quit_blender(), again while Blender refuses it, and
    give_up() if Blender still runs QUIT_GRACE_S later: the quit is only
    scheduled, and a test once waited for its 600 s timeout on a Blender
    left idle (a fresh-clone CI run, session 15; not reproduced in 27
    runs). A quit refused for QUIT_DIRECTLY_S goes through
    with_writes_allowed: Blender 3.4 under Xvfb refused every quit
    for the whole grace after a script's work was done (a CI run of
    session 48, and earlier ones), the refusal described above, and the
    test failed although Blender had done all that it was asked."""
    bpy.app.timers.register(lambda: give_up("QUIT: Blender did not end"),
                            first_interval=QUIT_GRACE_S)
    if _quit_refused():
        bpy.app.timers.register(_quit_again, first_interval=REFUSED_RETRY_S)


def _quit_refused():
    return refused_for_now(bpy.ops.wm.quit_blender, "QUIT", QUIT_DIRECTLY_S)


def _quit_again():
    return REFUSED_RETRY_S if _quit_refused() else None


def walk_steps(steps, label, interval=0.3, persistent=False):
    """Runs the generator `steps` a step per timer tick, `interval` seconds
    apart (the window redraws between them), then prints 'LABEL: DONE' and
    quits Blender; a `persistent` walk goes on after a file is opened."""
    def tick():
        try:
            next(steps)
        except StopIteration:
            print(f"{label}: DONE", flush=True)
            quit_blender()
            return None
        return interval

    guarded_timer(tick, 0.5, persistent=persistent)
