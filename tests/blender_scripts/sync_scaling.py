# SPDX-License-Identifier: GPL-2.0-or-later
"""Run by tests/test_addon.py: how much of the file one sync of the add-on's
hook reads, against the file's size. For each count given, the scenes of
bench/addon_sync.py (every other one with HBAO nodes), one sync to make the
helpers, then a second sync with the add-on's lookup of a tree's managed
node counted, and the node timer's refresh (no render done) likewise.
Prints SCALING {json}: {count: [calls in the sync, calls in the refresh]}.

  blender -b --addons hbao --python sync_scaling.py -- COUNT...
"""
import importlib.util
import json
import os
import sys

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
spec = importlib.util.spec_from_file_location("addon_sync",
                                              os.path.join(REPO, "bench", "addon_sync.py"))
addon_sync = importlib.util.module_from_spec(spec)
spec.loader.exec_module(addon_sync)

from hbao import handlers, helper_lookup, recomposite  # noqa: E402


def counted(function):
    """The calls of helper_lookup.managed_node that `function()` makes."""
    calls = [0]
    original = helper_lookup.managed_node

    def managed_node(tree):
        calls[0] += 1
        return original(tree)
    helper_lookup.managed_node = managed_node
    try:
        function()
    finally:
        helper_lookup.managed_node = original
    return calls[0]


found = {}
for count in [int(text) for text in sys.argv[sys.argv.index("--") + 1:]]:
    addon_sync.build(count)
    handlers._sync_everything()
    found[count] = [counted(handlers._sync_everything),
                    counted(lambda: recomposite.refresh_changed(in_background=True))]
print("SCALING", json.dumps(found), flush=True)
