# SPDX-License-Identifier: GPL-2.0-or-later
"""What a test script prints where Blender refused one of its steps or its
quit for good and it ran that with writes allowed (timer_guard.py): the
line "LABEL: refused for S s; WITH_WRITES_ALLOWED". Without bpy, so that
tests/conftest.py can list such runs in the test summary."""
import re

WITH_WRITES_ALLOWED = "running it with writes allowed, through a window-manager property's update"


def stuck_labels(log):
    """The labels (STEP, F12, QUIT...) of the lines above in a script's log,
    in order."""
    return re.findall(r"^(\w+): refused for [0-9.]+ s; " + re.escape(WITH_WRITES_ALLOWED),
                      log, flags=re.MULTILINE)
