# SPDX-License-Identifier: GPL-2.0-or-later
"""Editing Blender data the way the hook needs it everywhere."""


def set_if_different(owner, attribute, value):
    """Assign only real changes: every assignment tags Blender data for update."""
    if getattr(owner, attribute) != value:
        setattr(owner, attribute, value)
        return True
    return False
