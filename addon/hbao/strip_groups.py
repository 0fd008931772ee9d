# SPDX-License-Identifier: GPL-2.0-or-later
"""The compositor node groups that a scene's sequencer strips use: Blender
5.x's Compositor strip modifier, and 5.3's Compositor strip. They composite
a strip's image without a render's passes, so an HBAO node there gets no
AO (node_place.py says so)."""
from .strip_cameras import every_strip


def groups_of(scene):
    """[(strip, node group)] of `scene`'s sequencer, meta strips' too."""
    editor = getattr(scene, "sequence_editor", None)
    found = []
    for strip in every_strip(editor) if editor is not None else ():
        holders = [strip] + list(getattr(strip, "modifiers", ()))
        found += [(strip, holder.node_group) for holder in holders
                  if getattr(holder, "node_group", None) is not None]
    return found
