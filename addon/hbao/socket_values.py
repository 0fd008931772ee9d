# SPDX-License-Identifier: GPL-2.0-or-later
"""An HBAO node's settings at the frame being rendered: its sockets' values,
keyframed or fed by a Value node, resolved into library parameters."""
from . import compat, parameters
from .node import VALUE_INPUTS

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
    warnings.append(f"{socket.node.name}: {socket.name} comes from {source.node.name!r}; "
                    f"only a Value node can drive it, using {socket.default_value:g}")
    return socket.default_value


def node_params(node, frame, warnings):
    """The params dict for native.compute_ao() from the node at `frame`,
    resolved (completed and clamped) once, by parameters.resolved; each
    clamped value adds a warning naming the node. Raises ValueError naming
    the node when a value cannot be used at all (not a number, negative)."""
    tree = node.id_data
    raw = {
        "falloff": node.falloff,
        "integration": node.integration,
        "half_resolution": int(node.half_resolution),
        "blur_sharpness": float(node.blur_sharpness),
    }
    for name, (key, *_range) in VALUE_INPUTS.items():
        raw[key] = float(socket_value(tree, node.inputs[name], frame, warnings))
    clamped = []
    try:
        params = parameters.resolved(raw, clamped)
    except ValueError as error:
        raise ValueError(f"{node.name}: {error}") from error
    warnings += [f"{node.name}: {message}" for message in clamped]
    return params
