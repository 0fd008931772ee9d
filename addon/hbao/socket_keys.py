# SPDX-License-Identifier: GPL-2.0-or-later
"""A value socket's keyframes, kept across a rebuild of its node's group:
bpy 5.3 deletes a socket's F-Curve with the group socket that the rebuild
of the shared group removes (4.5 and 5.0 keep it), node_group.py."""
from . import compat


def saved(socket):
    """{"extrapolation", "keys": [frame, value, interpolation, easing,
    handle types and handles] each} of a one-value socket's F-Curve, or {}
    (JSON: it is kept on the node while the group changes)."""
    if hasattr(socket.default_value, "__len__"):
        return {}
    fcurve = compat.find_fcurve(socket.id_data, socket.path_from_id("default_value"))
    if fcurve is None:
        return {}
    return {"extrapolation": fcurve.extrapolation,
            "keys": [[key.co[0], key.co[1], key.interpolation, key.easing,
                      key.handle_left_type, key.handle_right_type, list(key.handle_left),
                      list(key.handle_right)] for key in fcurve.keyframe_points]}


def restore(socket, state):
    """The socket's keyframes again (saved()), where its F-Curve is gone."""
    keys = state.get("keys", []) if isinstance(state, dict) else []
    path = socket.path_from_id("default_value")
    if not keys or compat.find_fcurve(socket.id_data, path) is not None:
        return
    for frame, value, *_rest in keys:
        socket.default_value = int(round(value)) if isinstance(socket.default_value, int) \
            else value
        socket.keyframe_insert("default_value", frame=frame)
    fcurve = compat.find_fcurve(socket.id_data, path)
    if fcurve is None:
        return
    fcurve.extrapolation = state.get("extrapolation", fcurve.extrapolation)
    by_frame = {key[0]: key for key in keys}
    for point in fcurve.keyframe_points:
        key = by_frame.get(point.co[0])
        if key is not None:
            point.interpolation, point.easing = key[2], key[3]
            point.handle_left_type, point.handle_right_type = key[4], key[5]
            point.handle_left, point.handle_right = key[6], key[7]
