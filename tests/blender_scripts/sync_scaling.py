# SPDX-License-Identifier: GPL-2.0-or-later
"""Run by tests/test_addon.py: how much of the file one sync of the add-on's
hook reads, against the file's size. For each count given, the scenes of
bench/addon_sync.py (every other one with HBAO nodes), one sync to make the
helpers, then a second sync with the add-on's lookup of a tree's managed
node counted, and the node timer's refresh (no render done) likewise; and
the walks of every sequencer strip for the strips' Camera overrides in that
sync, and the reads of a scene's stack of compositor effects (5.3; none
before) in that sync. Prints SCALING {json}: {count: [lookups in the sync,
lookups in the refresh, walks of the strips in the sync, reads of the
effects in the sync]}.

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

from hbao import (compositor_effects, handlers, helper_lookup, recomposite,  # noqa: E402
                  strip_cameras)


def counted(function, module=helper_lookup, name="managed_node"):
    """The calls of module.name that `function()` makes."""
    calls = [0]
    original = getattr(module, name)

    def count(*args):
        calls[0] += 1
        return original(*args)
    setattr(module, name, count)
    try:
        function()
    finally:
        setattr(module, name, original)
    return calls[0]


found = {}
for count in [int(text) for text in sys.argv[sys.argv.index("--") + 1:]]:
    addon_sync.build(count)
    handlers._sync_everything()
    found[count] = [counted(handlers._sync_everything),
                    counted(lambda: recomposite.refresh_changed(in_background=True)),
                    counted(handlers._sync_everything, strip_cameras, "_overrides_by_scene"),
                    counted(handlers._sync_everything, compositor_effects, "served_effect")]
print("SCALING", json.dumps(found), flush=True)
