# SPDX-License-Identifier: GPL-2.0-or-later
"""Run inside Blender by tests/test_addon.py: addon_render.py, with the
add-on's AO computation watched. Each time a node's AO has been computed,
the names in the scratch folder (HBAO_TEMP_DIR) are noted: the frame's
scratch file must still be there, its removal left until the AO is done
(scratch_files.removals_after). Prints them as 'SCRATCH AT AO <json>'.

  blender -b --addons hbao --python removal_order.py -- '<json spec>' <out dir>
"""
import json
import os
import runpy

from hbao import layer_passes

RENDER_SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "addon_render.py")
folder = os.environ["HBAO_TEMP_DIR"]
seen = []
compute = layer_passes.compute


def watched(*args, **kwargs):
    ao = compute(*args, **kwargs)
    seen.append(sorted(os.listdir(folder)))
    return ao


layer_passes.compute = watched  # the add-on's own function, which helper_ao.py calls
runpy.run_path(RENDER_SCRIPT, run_name="__main__")
print("SCRATCH AT AO", json.dumps(seen), flush=True)
