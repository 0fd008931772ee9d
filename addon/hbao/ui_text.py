# SPDX-License-Identifier: GPL-2.0-or-later
"""Long messages as the lines of a panel (the sidebar, the preferences):
Blender's labels do not wrap, and cut a long one in the middle. No bpy."""
import re
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


# A node's status line longer than this is cut with an ellipsis: what the
# node's default width shows beside the line's icon at 100 % zoom (Blender
# 3.4 cut 30 to about 25, losing a "(+2)"; a review's find). The full text
# is the tooltip.
MAX_STATUS_CHARACTERS = 25


def status_line(short):
    """`short` (a node's status, node_status.show_messages) as it fits the
    node: cut with an ellipsis, the count of further messages, " (+N)",
    kept whole."""
    if len(short) <= MAX_STATUS_CHARACTERS:
        return short
    more = re.search(r" \(\+\d+\)$", short)
    suffix = more.group(0) if more else ""
    return short[:MAX_STATUS_CHARACTERS - 1 - len(suffix)] + "\u2026" + suffix
