# SPDX-License-Identifier: GPL-2.0-or-later
"""The node's status line as it fits the node (ui_text.status_line, bpy-free)."""
from conftest import REPO  # noqa: F401  (puts the add-on on sys.path)
from hbao import native, ui_text


def test_a_short_status_is_shown_whole():
    for short in ("Depth not linked: AO off", "Compositing off: no AO", ""):
        assert ui_text.status_line(short) == short


def test_a_long_status_keeps_its_count_of_further_messages():
    """Blender 3.4 cut "Directions clamped to 64 (+2)" at the node's width
    to "Directions clamped to 64 ...", and the "(+2)" that says more
    messages wait in the tooltip was lost (a review's find)."""
    shown = ui_text.status_line("Directions clamped to 64 (+2)")
    assert shown == "Directions clamped \u2026 (+2)" and len(shown) == ui_text.MAX_STATUS_CHARACTERS
    cut = ui_text.status_line("A status line of thirty-two chars")
    assert cut == "A status line of thirty-\u2026"
    assert len(cut) == ui_text.MAX_STATUS_CHARACTERS


def test_the_library_notes_short_forms_fit_the_node():
    for short in native.NOTE_SHORT_FORMS.values():
        assert ui_text.status_line(short) == short
