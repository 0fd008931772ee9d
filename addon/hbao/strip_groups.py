# SPDX-License-Identifier: GPL-2.0-or-later
"""The compositor node groups that a scene's sequencer strips use: Blender
5.x's Compositor strip modifier, and 5.3's Compositor strip. They composite
a strip's image without a render's passes, so an HBAO node there gets no
AO (node_place.py says so)."""
from .strip_cameras import every_strip


def groups_of(scene, rendered=False):
    """[(strip, node group)] of `scene`'s sequencer, meta strips' too;
    `rendered`: only those a render of `scene` composites (the sequencer on
    for renders; the strip, its channel, a meta strip around it and the
    modifier not muted)."""
    editor = getattr(scene, "sequence_editor", None)
    if editor is None or (rendered and not scene.render.use_sequencer):
        return []
    found = []
    for strip in every_strip(editor, unmuted=rendered):
        holders = [strip] + list(getattr(strip, "modifiers", ()))
        found += [(strip, holder.node_group) for holder in holders
                  if getattr(holder, "node_group", None) is not None
                  and not (rendered and getattr(holder, "mute", False))]
    return found
