# SPDX-License-Identifier: GPL-2.0-or-later
"""What a test script prints where Blender refused its quit for good and it
quit with writes allowed (timer_guard.py). Without bpy, so that
tests/conftest.py can list such runs in the test summary."""
QUIT_WITH_WRITES_ALLOWED = "quitting through a window-manager property's update"
