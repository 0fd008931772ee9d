# SPDX-License-Identifier: GPL-2.0-or-later
"""Long messages as the lines of a panel (the sidebar, the preferences):
Blender's labels do not wrap, and cut a long one in the middle. No bpy."""
import textwrap

# About how wide a character of the interface's text is, in pixels at a
# resolution scale of 1, and what a box and an icon take of a line.
CHARACTER_PIXELS = 7.0
LINE_MARGIN_PIXELS = 50


def characters_for(width, scale=1.0):
    """How many characters a label `width` pixels wide holds at interface
    scale `scale`."""
    return max(16, int((width - LINE_MARGIN_PIXELS * scale) / (CHARACTER_PIXELS * scale)))


def labels(layout, text, characters, icon="NONE"):
    """`text` as labels of at most `characters` characters, the first with
    `icon`, the others indented as if they had one."""
    for number, line in enumerate(textwrap.wrap(text, characters)):
        layout.label(text=line, icon=icon if number == 0 else "BLANK1")
