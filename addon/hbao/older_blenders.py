# SPDX-License-Identifier: GPL-2.0-or-later
"""The HBAO nodes' settings kept where Blenders before 5.0 read them.

Blender 5.0 keeps the values of an add-on's properties (bpy.props: on the
node, Falloff, Integration, Half Resolution, Blur Sharpness, Guard Band,
Back Faces, Pass Index) apart from the node's custom properties, where
Blenders before 5.0 keep and read them. So a file saved in 5.x and opened
in 4.5 (a farm on the LTS, a colleague's older Blender) gave every HBAO
node those settings' defaults, or the values of the file's last save by
an older Blender, and said nothing (an exploratory run; the sockets'
values survive). Before each save in 5.x the settings are copied into
custom properties of the same names, which an older Blender reads as its
own; 5.x reads the values it keeps itself, and a file saved back by 4.5
gives 5.x the values 4.5 saved (Blender moves them over on opening it).
5.x's Custom Properties panel of the active node lists a custom property
that has a property's name only with Developer Extras on
(rna_prop_ui.draw), so artists do not see the copies."""
import bpy

from .compositor_effects import is_hbao_node

# The kinds of property copied: the settings. Statuses and hints (strings)
# are written by each render, which says them again.
_SETTING_TYPES = frozenset({"ENUM", "BOOLEAN", "INT", "FLOAT"})


def _as_stored(node, prop):
    """The node's value of `prop` as a Blender before 5.0 stores it: an
    enum as its item's number, a boolean as 0 or 1."""
    value = getattr(node, prop.identifier)
    if prop.type == "ENUM":
        return prop.enum_items[value].value
    if prop.type == "BOOLEAN":
        return int(value)
    return value


def copy_node_settings():
    """In Blender 5.0 and later: every HBAO node's settings of this file
    (not a linked library's) into its custom properties of the same names,
    where they differ. Returns how many values it wrote."""
    if bpy.app.version < (5, 0, 0):
        return 0
    written = 0
    for tree in bpy.data.node_groups:
        if tree.library is not None:
            continue
        for node in tree.nodes:
            if is_hbao_node(node):
                try:
                    written += _copy(node)
                except (AttributeError, RuntimeError, TypeError):
                    continue  # a node Blender will not let us write: the next one
    return written


def _copy(node):
    written = 0
    for prop in node.bl_rna.properties:
        if not prop.is_runtime or prop.is_readonly or prop.type not in _SETTING_TYPES \
                or getattr(prop, "is_array", False):
            continue
        value = _as_stored(node, prop)
        if node.get(prop.identifier) != value:
            node[prop.identifier] = value
            written += 1
    return written
