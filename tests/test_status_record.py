# SPDX-License-Identifier: GPL-2.0-or-later
"""What a node keeps of its status line in a saved file (report.record_of,
messages_in; bpy-free): the messages come back with their short forms and
causes, so that the add-on can check the causes once the file is opened
again (tests/test_faults_ui.py has the whole path in Blender)."""
from conftest import REPO  # noqa: F401  (puts the add-on on sys.path)
from hbao import report


def test_a_record_gives_back_its_messages_and_their_causes():
    said = [report.NodeMessage("HBAO \"é\"", "Compositing is off; no AO", "Compositing off: no AO",
                               ("compositing off",)),
            report.NodeMessage("HBAO \"é\"", "Depth is not linked; AO off",
                               "Depth not linked: AO off", ("plan", 12.5)),
            report.NodeMessage("HBAO \"é\"", "the AO's own note", "Radius < 1 pixel: no AO")]
    kept = report.messages_in("HBAO \"é\"", report.record_of(said))
    assert kept == said  # the full texts
    assert [(m.node_name, m.detail, m.short, m.cause) for m in kept] == \
        [(m.node_name, m.detail, m.short, m.cause) for m in said]


def test_no_messages_keep_nothing_and_a_bad_record_gives_none():
    assert report.record_of([]) == ""
    assert report.messages_in("HBAO", "") == []
    for bad in ("{", "3", "[1, 2]", "[[\"a\"]]", "null"):
        assert report.messages_in("HBAO", bad) == [], bad
