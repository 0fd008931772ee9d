# SPDX-License-Identifier: GPL-2.0-or-later
"""What the helper scene's AO passes hold: the occlusion, 1 - AO, so that a
pass nobody wrote (0) means no AO. The node's group turns it back (its Math
node, group_layout.py: AO = 1 - pass), as node_ao does here (the tests hold
the two together: tests/conftest.py's node_native). Both are one float32
subtraction: the node's AO is the library's exactly where the AO is 0.5 or
more, and within 2^-25 below (a multiple of 2^-24 there).

The pass holds the AO itself for a node whose group is older than layout
FIRST_OCCLUSION_LAYOUT: a scene linked from a file saved before it (the
add-on cannot rebuild a library's group), or appended by a script that
renders before the add-on gave the node the current group. bpy-free."""
import numpy as np

# The first layout of the node's group (group_layout.GROUP_TREE_VERSION) whose
# pass holds the occlusion.
FIRST_OCCLUSION_LAYOUT = 5
# What every pass holds where no AO was computed for it (layout 5 on).
NO_OCCLUSION = 0.0


def occlusion_pass(ao):
    """The pass the engine writes for the library's AO (float32 array)."""
    return np.float32(1.0) - np.asarray(ao, np.float32)


def node_ao(occlusion):
    """The AO the node outputs for a pass (its group's 1 - pass)."""
    return np.float32(1.0) - np.asarray(occlusion, np.float32)


def pass_for_layout(ao, layout):
    """The pass for the AO of a node whose group has layout `layout`."""
    return occlusion_pass(ao) if layout >= FIRST_OCCLUSION_LAYOUT else np.asarray(ao, np.float32)


def no_ao_for_layout(layout):
    """The pass value (and pass input value) that means no AO for a node
    whose group has layout `layout`."""
    return NO_OCCLUSION if layout >= FIRST_OCCLUSION_LAYOUT else 1.0
