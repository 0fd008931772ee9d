# SPDX-License-Identifier: GPL-2.0-or-later
"""An HBAO node's settings at the frame being rendered: its sockets' values,
keyframed or fed by a Value node, resolved into library parameters."""
from . import compat, native, parameters
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


def _animated(id_data, owner, attribute, frame, fallback):
    """owner.attribute at `frame` if an F-Curve animates it, else `fallback`.
    The render may run in another thread than the depsgraph that evaluates
    animation, so the F-Curve is evaluated here directly."""
    try:
        path = owner.path_from_id(attribute)
    except ValueError:
        return fallback
    fcurve = compat.find_fcurve(id_data, path)
    return fcurve.evaluate(frame) if fcurve is not None else fallback


def socket_value(tree, socket, frame, warnings):
    """The number `socket` carries at `frame`: its own (animated) value, or
    that of the Value node linked to it."""
    source = upstream(socket)
    if source is None:
        return _animated(tree, socket, "default_value", frame, socket.default_value)
    if source.node.bl_idname in compat.VALUE_NODE_IDNAMES:
        return _animated(tree, source, "default_value", frame, source.default_value)
    warnings.append(NodeMessage(
        socket.node.name, f"{socket.name} comes from {source.node.name!r}; only a Value node "
        f"can drive it, using {socket.default_value:g}", f"{socket.name}: use a Value node"))
    return socket.default_value


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


def node_params(node, frame, warnings):
    """The params dict for native.compute_ao() from the node at `frame`,
    resolved (completed and clamped) once, by the library (native.resolve_params); each
    clamped value adds a NodeMessage. Raises ValueError when a value cannot
    be used at all (not a number, negative), its `short` attribute the form
    that fits the node's status line."""
    tree = node.id_data
    raw = {
        "falloff": node.falloff,
        "integration": node.integration,
        "half_resolution": int(node.half_resolution),
        "blur_sharpness": float(node.blur_sharpness),
    }
    for name, (key, *_socket) in VALUE_INPUTS.items():
        raw[key] = float(socket_value(tree, node.inputs[name], frame, warnings))
    clamped = []
    try:
        params = native.resolve_params(raw, clamped)
    except ValueError as error:
        unusable = ValueError(str(error))
        unusable.short = _short_error(str(error))
        raise unusable from error
    warnings += [NodeMessage(node.name, message, _short_clamp(message)) for message in clamped]
    return params
