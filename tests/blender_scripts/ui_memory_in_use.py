# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in a real Blender window (xvfb) by tests/test_ui.py: the add-on's
timer (memory_hold._poll) must not hand the library's memory back while
the library is in use outside a render (a re-composite's worker:
memory_hold.in_use), and the hold starts at that use's end.

With Keep Memory After a Render at 0 s, the memory is held (start_hold),
then a thread stays in memory_hold.in_use() for USE_S seconds, over
several of the timer's one-second looks, each of which would release a
hold of 0 s. memory_hold's calls of native.release_memory are counted.
Prints 'IN_USE {"releases_during": how many came while the thread was in
the block, "held_at_end": memory_hold.held() as it left, "release_after_s":
seconds from its end to the first release after it, or null}', then
'IN_USE: DONE'.

  blender --addons hbao --python ui_memory_in_use.py
"""
import json
import os
import sys
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import timer_guard  # noqa: E402
from hbao_preferences import hbao_preferences  # noqa: E402

USE_S = 2.5
# How long after the use's end the release may come (the timer looks every second).
RELEASE_LATE_S = 10.0

memory_hold = sys.modules["hbao.memory_hold"]
hbao_preferences().keep_memory_s = 0

releases = []  # time.monotonic() of each release memory_hold asked for
release_memory = memory_hold.native.release_memory


def counted_release():
    releases.append(time.monotonic())
    release_memory()


memory_hold.native.release_memory = counted_release
use = {}


def use_the_library():
    with memory_hold.in_use():
        use["began"] = time.monotonic()
        time.sleep(USE_S)
        use["ending"] = time.monotonic()
    use["held_at_end"] = memory_hold.held()
    use["ended"] = time.monotonic()


def steps():
    memory_hold.start_hold()
    thread = threading.Thread(target=use_the_library, daemon=True)
    thread.start()
    while thread.is_alive():
        yield
    while not any(t > use["ended"] for t in releases):
        if time.monotonic() - use["ended"] > RELEASE_LATE_S:
            break
        yield
    after = [t - use["ended"] for t in releases if t > use["ended"]]
    report = {
        "releases_during": sum(use["began"] <= t <= use["ending"] for t in releases),
        "held_at_end": use["held_at_end"],
        "release_after_s": after[0] if after else None,
    }
    print(f"IN_USE {json.dumps(report)}", flush=True)


timer_guard.walk_steps(steps(), "IN_USE", interval=0.1)
