# SPDX-License-Identifier: GPL-2.0-or-later
"""Run inside Blender by tests/test_addon.py on a file that ui_old_file.py
saved (the shared group at version 1, Blur Size keyed 3 at frame 1 and 9 at
frame 11, Radius keyed with easing, extrapolation and modifiers): opening it
upgraded the group (load_post). Prints UPGRADE {json}: the socket types,
Directions, where Steps comes from, Blur Size at frames 1, 6 and 11, the
Radius curve's settings and values, and the group's version.

  blender -b OLD.blend --addons hbao --python old_file_upgrade.py
"""
import json
import sys

import bpy

compat = sys.modules["hbao.compat"]
group_layout = sys.modules["hbao.group_layout"]
socket_values = sys.modules["hbao.socket_values"]
tree = compat.compositor_tree(bpy.context.scene)


def modifier_settings(modifier):
    """Some of the settings ui_old_file.py gave each of its modifiers."""
    if modifier.type == "CYCLES":
        return [modifier.mode_after, modifier.cycles_after]
    range_ = [modifier.use_restricted_range, modifier.frame_start, modifier.frame_end]
    if modifier.type == "ENVELOPE":
        return range_ + [[[point.frame, point.min, point.max]
                          for point in modifier.control_points]]
    return range_ + [modifier.strength]


def radius_curve():
    """What the artist set on the Radius curve (ui_old_file.py), and its
    value at frames 1 .. 60; None where the curve is gone."""
    node = tree.nodes["HBAO"]
    curve = compat.find_fcurve(tree, node.inputs["Radius"].path_from_id("default_value"))
    if curve is None:
        return None
    keys = curve.keyframe_points
    return {
        "first": [keys[0].interpolation, keys[0].easing, keys[0].back],
        "last_type": keys[-1].type,
        "extrapolation": curve.extrapolation,
        "modifiers": [[modifier.type] + modifier_settings(modifier)
                      for modifier in curve.modifiers],
        "values": {frame: curve.evaluate(frame) for frame in range(1, 61)},
    }


node = tree.nodes["HBAO"]
blur = node.inputs["Blur Size"]
print("UPGRADE", json.dumps({
    "current": bpy.data.node_groups[group_layout.GROUP_TREE_NAME].get(
        group_layout.GROUP_VERSION_KEY) == group_layout.GROUP_TREE_VERSION,
    "socket_types": {name: node.inputs[name].bl_idname
                     for name in ("Directions", "Steps", "Blur Size")},
    "directions": node.inputs["Directions"].default_value,
    "steps_source": [link.from_node.name for link in node.inputs["Steps"].links],
    "blur": [socket_values.socket_value(blur, float(frame), []) for frame in (1, 6, 11)],
    "ao_pass_value": node.inputs[group_layout.AO_PASS_INPUT].default_value,
    "grouped_directions": bpy.data.node_groups["Artist Group"].nodes[
        "Grouped HBAO"].inputs["Directions"].default_value,
    "radius_curve": radius_curve(),
    "drivers": [[tree.path_resolve(driver.data_path.rsplit(".", 1)[0]).name,
                 driver.driver.expression,
                 [[variable.name, variable.type, variable.targets[0].id_type,
                   getattr(variable.targets[0].id, "name", None), variable.targets[0].data_path,
                   variable.targets[0].transform_type] for variable in driver.driver.variables],
                 len(driver.modifiers), [list(key.co) for key in driver.keyframe_points]]
                for driver in getattr(tree.animation_data, "drivers", ())],
}), flush=True)
