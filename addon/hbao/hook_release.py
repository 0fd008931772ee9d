# SPDX-License-Identifier: GPL-2.0-or-later
"""The hook let go when the add-on is disabled in a session (Preferences,
Reload Scripts, before a removal, as Blender quits).

Each HBAO node's AO pass input is linked to the managed Render Layers node,
whose helper scene only the add-on's engine renders. Disabled, Blender
renders that scene with another engine, which writes no such pass (before
the group's layout 5, whose pass holds the occlusion, the node then read 0
and the final image was black: Blender 3.4, which keeps the node's class,
and bpy 5.3). So the pass input is unlinked (its value is then "no AO": the
node passes Image through) and the managed node muted, so that Blender does
not render the helper scene at all. Enabled again, the add-on's sync links
and unmutes them (helper_scene.py)."""
import bpy

from . import compat
from .data_edits import set_if_different
from .helper_lookup import managed_node
from .node import AO_PASS_INPUT, hbao_nodes
from .group_layout import no_ao_value
from .report import log


def release_all():
    """Every scene's hook let go; a scene that Blender will not let change
    now (writes.py) keeps its own, said in the console."""
    for scene in list(getattr(bpy.data, "scenes", ())):
        try:
            _release(compat.compositor_tree(scene))
        except Exception as error:  # the rest of the add-on still goes
            log(f"could not let go of the HBAO hook of {scene.name!r}: {error}")


def _release(tree):
    rlayers = managed_node(tree)
    if rlayers is None:
        return
    unlink_ao_inputs(tree)
    set_if_different(rlayers, "mute", True)


def unlink_ao_inputs(tree):
    """The AO pass inputs of `tree`'s HBAO nodes unlinked and set to no AO:
    the nodes pass Image through."""
    for node in hbao_nodes(tree):
        unlink_ao_input(tree, node)


def unlink_ao_input(tree, node):
    """`node`'s AO pass input unlinked and set to no AO (as its group reads it)."""
    target = node.inputs.get(AO_PASS_INPUT)
    if target is None:
        return
    for link in list(target.links):
        tree.links.remove(link)
    set_if_different(target, "default_value", no_ao_value(node))
