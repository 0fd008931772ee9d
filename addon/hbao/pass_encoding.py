# SPDX-License-Identifier: GPL-2.0-or-later
"""What the helper scene's AO passes hold: the occlusion, 1 - AO, so that a
pass nobody wrote (0) means no AO. The node's group turns it back (its Math
node, node_group.py: AO = 1 - pass), as node_ao does here. Both are one
float32 subtraction: the node's AO is the library's exactly where the AO is
0.5 or more, and within 2^-25 below (a multiple of 2^-24 there). bpy-free."""
import numpy as np

# What every pass holds where no AO was computed for it.
NO_OCCLUSION = 0.0


def occlusion_pass(ao):
    """The pass the engine writes for the library's AO (float32 array)."""
    return np.float32(1.0) - np.asarray(ao, np.float32)


def node_ao(occlusion):
    """The AO the node outputs for a pass (its group's 1 - pass)."""
    return np.float32(1.0) - np.asarray(occlusion, np.float32)
