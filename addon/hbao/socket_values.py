# SPDX-License-Identifier: GPL-2.0-or-later
"""An HBAO node's settings at the frame being rendered: its sockets' values,
keyframed or fed by a Value node, and its menus and checkboxes, keyframed,
resolved into library parameters."""
from . import compat, native, parameters, socket_keys
from .node import VALUE_INPUTS
from .report import NodeMessage

# Reroute chains longer than this are treated as unlinked (a cycle guard).
MAX_REROUTES = 64


def upstream(socket):
    """The output socket that really feeds `socket`, through reroutes; None if unlinked."""
    seen = 0
    while socket is not None and socket.is_linked and seen < MAX_REROUTES:
        link = socket.links[0]
        if link.is_muted or not link.is_valid:
            return None
        from_socket = link.from_socket
        if from_socket.node.bl_idname == "NodeReroute":
            socket = from_socket.node.inputs[0]
            seen += 1
            continue
        return from_socket
    return None


# C's FLT_EPSILON
_FLOAT_EPSILON = 2.0 ** -23


def animation_time(main, frame):
    """The time at which Blender evaluates animation for `frame` (a float,
    with its subframe) of `main`'s render: Time Remapping (Output > Frame
    Range, Old and New) scales it, the camera's and the node's alike."""
    return frame * main.render.frame_map_old / main.render.frame_map_new


def _not_followed(id_data, path):
    """What animates `path` that the hook does not evaluate, in long and
    short form (("a driver", "driver"), ("NLA strips", "NLA")), or None:
    a driver not muted; strips Blender evaluates (the NLA on, their track
    the solo one where one is, neither muted; not inside meta strips)."""
    animation = getattr(id_data, "animation_data", None)
    if animation is None:
        return None
    driver = socket_keys.driver_fcurve(id_data, path)
    if driver is not None and not driver.mute:
        return "a driver", "driver"
    tracks = list(animation.nla_tracks) if animation.use_nla else []
    solo = [track for track in tracks if track.is_solo]
    for track in solo or tracks:
        for strip in track.strips if not track.mute else ():
            if not strip.mute and compat.action_fcurve(
                    strip.action, getattr(strip, "action_slot", None), path) is not None:
                return "NLA strips", "NLA"
    return None


def _animated(owner, attribute, time, node_name, label, notes):
    """owner.attribute at `time` if the tree's active action animates it (an
    F-Curve not muted), else None. The render may run in another thread than
    the depsgraph that evaluates animation, and a render's own depsgraph
    writes nothing back to the file's data: the F-Curve is evaluated here
    directly. A driver or NLA strips on it add a NodeMessage to `notes`:
    every frame then uses the F-Curve, or else the stored value."""
    id_data = owner.id_data
    try:
        path = owner.path_from_id(attribute)
    except ValueError:
        return None
    other = _not_followed(id_data, path)
    if other is not None:
        other, short = other
        notes.append(NodeMessage(
            node_name, f"{label} is animated by {other}, which the HBAO hook does not "
            "evaluate at each frame: an animation render uses the node tree's own keyframes, "
            "else the value Blender shows now; key it in the tree's action or use a Value "
            "node", f"{label}: fixed ({short})"))
    fcurve = compat.find_fcurve(id_data, path)
    return fcurve.evaluate(time) if fcurve is not None and not fcurve.mute else None


def socket_value(socket, time, warnings, notes=None):
    """The number `socket` carries at `time` (animation_time): its own
    (animated) value, or that of the Value node linked to it. Problems go to
    `warnings`, animation that is not followed to `notes` (or `warnings`)."""
    notes = warnings if notes is None else notes
    node_name = socket.node.name
    source = upstream(socket)
    if source is None:
        value = _animated(socket, "default_value", time, node_name, socket.name, notes)
        return socket.default_value if value is None else value
    if source.node.bl_idname in compat.VALUE_NODE_IDNAMES:
        value = _animated(source, "default_value", time, node_name, socket.name, notes)
        return source.default_value if value is None else value
    warnings.append(NodeMessage(
        node_name, f"{socket.name} comes from {source.node.name!r}; only a Value node "
        f"can drive it, using {socket.default_value:g}", f"{socket.name}: use a Value node"))
    return socket.default_value


def property_value(node, attribute, time, notes):
    """The node's property `attribute` at `time`, keyframed or not (menus
    and checkboxes as Blender writes an F-Curve's value into them: an enum
    truncated, a boolean true above 1 - FLT_EPSILON; keyframe_insert's
    curves hold whole numbers anyway)."""
    prop = node.bl_rna.properties[attribute]
    value = _animated(node, attribute, time, node.name, prop.name, notes)
    if value is None:
        return getattr(node, attribute)
    if prop.type == "ENUM":
        return next((item.identifier for item in prop.enum_items
                     if item.value == int(value)), getattr(node, attribute))
    if prop.type == "BOOLEAN":
        return value > 1.0 - _FLOAT_EPSILON
    return value


def _label_of(message):
    """The parameter a native.resolve_params() message is about (it starts with its label)."""
    return next((label for label in sorted(parameters.LABELS.values(), key=len, reverse=True)
                 if message.startswith(label)), "A value")


def _short_error(message):
    label = _label_of(message)
    what = ("not a number" if "not a number" in message
            else "negative" if "negative" in message else "invalid")
    return f"{label} {what}: AO off"


def _short_clamp(message):
    return f"{_label_of(message)} clamped to {message.rsplit('using ', 1)[-1]}"


def node_params(node, main, frame, warnings):
    """The params dict for native.compute_ao() from the node at `frame` of
    `main`'s render, resolved (completed and clamped) once, by the library
    (native.resolve_params); each clamped value adds a NodeMessage. Raises
    ValueError when a value cannot be used at all (not a number, negative),
    its `short` attribute the form that fits the node's status line. Values
    animated in ways an animation render does not follow are said last."""
    time = animation_time(main, frame)
    notes = []
    raw = {
        "falloff": property_value(node, "falloff", time, notes),
        "integration": property_value(node, "integration", time, notes),
        "half_resolution": int(property_value(node, "half_resolution", time, notes)),
        "blur_sharpness": float(property_value(node, "blur_sharpness", time, notes)),
    }
    for name, (key, *_socket) in VALUE_INPUTS.items():
        raw[key] = float(socket_value(node.inputs[name], time, warnings, notes))
    clamped = []
    try:
        params = native.resolve_params(raw, clamped)
    except ValueError as error:
        unusable = ValueError(str(error))
        unusable.short = _short_error(str(error))
        raise unusable from error
    warnings += [NodeMessage(node.name, message, _short_clamp(message)) for message in clamped]
    warnings += notes
    return params
