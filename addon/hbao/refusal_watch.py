# SPDX-License-Identifier: GPL-2.0-or-later
"""When Blender's refusal of Python's writes has lasted long enough to be
the kind that does not end (docs/blender-integration.md, "Rarely the
refusal does not end"): two threads' callbacks that overlap out of order
leave Blender's flag set until it restarts, and Python's writes fail
(add-ons' timers and handlers, scripts). writes.py asks this at each of
its probes, tells the artist once, and from then on makes the add-on's own
writes where Blender still allows them (writes.run_writing). Without bpy,
so that plain pytest holds its rules (tests/test_refusal_watch.py)."""
import time

# Refused at every ask for this long, while no job that runs Python
# callbacks in another thread (a render, a bake) runs: stuck. A real
# refusal lasts as long as such a callback, and those run only inside jobs.
STUCK_AFTER_S = 5.0
# Asks further apart than this start the count again: two real refusals met
# by chance minutes apart are not one. The add-on's timers ask every 0.25 s
# while they have work; the margin is for the main loop's slow passes (a
# heavy viewport, a save; software OpenGL on a loaded machine: a test under
# CI's load once waited 20 s for the notice with 2.5 s here).
ASKED_WITHIN_S = 5.0

STUCK_SENTENCES = (
    "Blender has refused every change from Python for {seconds:.0f} s with no render running.",
    "It will until it restarts: a fault of Blender's (two of its callbacks overlapped).",
    "Other add-ons and scripts may stop working.",
    "Save the file and restart Blender.",
    "Meanwhile the HBAO nodes go on working: the add-on works around it.")


class RefusalWatch:
    """The refusals of one session's probes, as note() is told them."""

    def __init__(self, clock=time.monotonic):
        self._clock = clock
        self.reset()

    def reset(self):
        self._since = None
        self._last = None
        self.told = False
        self.lasted = None  # how long the refusal had lasted when it was told

    def note(self, allowed, job_running):
        """One probe's answer (`allowed`), and whether a job that runs Python
        callbacks runs now. Returns the seconds the refusal has lasted the
        first time it counts as stuck (to be told, once), else None. An
        allowed write ends it, and a later one can be told again."""
        if allowed or job_running:
            self._since = None
            if allowed:
                self.told, self.lasted = False, None
            return None
        now = self._clock()
        if self._since is None or now - self._last > ASKED_WITHIN_S:
            self._since = now
        self._last = now
        if self.told or now - self._since < STUCK_AFTER_S:
            return None
        self.told, self.lasted = True, now - self._since
        return self.lasted


def stuck_sentences(seconds):
    """What the artist is told, a sentence a line."""
    return [sentence.format(seconds=seconds) for sentence in STUCK_SENTENCES]


def stuck_text(seconds):
    """The same as one text (the console, a tooltip)."""
    return " ".join(stuck_sentences(seconds))
