# SPDX-License-Identifier: GPL-2.0-or-later
"""Where an HBAO node's Depth and Normal come from: the Render Layers pass
that feeds each input, why the node refuses a source (the one rule that the
render's plan, the pass switch below and Connect Passes share), and turning
on a pass the node reads but its view layer lacks."""
from . import compat, handover
from .helper_lookup import MANAGED_NODE_KEY
from .node import DEPTH_INPUT, NORMAL_INPUT, hbao_nodes
from .report import NodeMessage, add_node_messages, in_main_thread, log, note_change
from .socket_values import MAX_REROUTES

# (input, view layer attribute, label) of each pass a node reads
PASSES = ((DEPTH_INPUT, "use_pass_z", "Depth"), (NORMAL_INPUT, "use_pass_normal", "Normal"))


def render_layers_refusal(node, scene, label):
    """(error, short error) of why an HBAO node in `scene`'s compositor takes
    no `label` pass from Render Layers node `node`: it shows another scene's
    render, it is muted, or its view layer is not rendered; None if none."""
    if node.scene is not None and node.scene != scene:
        return f"{label} comes from another scene ({node.scene.name})", "other scene"
    if node.mute:
        return f"{label} comes from a muted Render Layers node ({node.name})", "muted"
    view_layer = scene.view_layers.get(node.layer)
    if view_layer is not None and not view_layer.use:
        return (f"{label} comes from view layer {node.layer!r}, which is not rendered (its "
                "Use for Rendering is off)", "not rendered")
    return None


def _feeding_output(socket):
    """(output socket, whether its link is valid, whether a link is muted)
    that feeds `socket` through reroutes; no output where it is unlinked or
    a link is muted. A link to a pass that is off is invalid in 5.x, and
    still says where it comes from."""
    valid = True
    for _reroute in range(MAX_REROUTES):
        if socket is None or not socket.is_linked:
            return None, False, False
        link = socket.links[0]
        if link.is_muted:
            return None, False, True
        valid = valid and link.is_valid
        if link.from_node.bl_idname != "NodeReroute":
            return link.from_socket, valid, False
        socket = link.from_node.inputs[0]
    return None, False, False


def _render_layers_pass(socket, expected):
    """(output socket, its link valid, error, short error): the Render
    Layers output that feeds `socket`; None for none (unlinked: no error),
    or for another kind of source, with its error."""
    source, valid, muted = _feeding_output(socket)
    if muted:
        return None, False, f"{socket.name}'s link is muted", "link muted"
    if source is None:
        return None, False, None, None
    node = source.node
    if node.bl_idname != "CompositorNodeRLayers" or node.get(MANAGED_NODE_KEY):
        # an Image node: a saved render, whose AO the CLI computes
        hint = (" (for a saved render's EXR, use the hbao command-line tool)"
                if node.bl_idname == "CompositorNodeImage" else "")
        return (None, False, f"{socket.name} must come straight from a Render Layers node"
                f"{hint}", "wrong source")
    if source.identifier != expected and source.name != expected:
        return (None, False, f"{socket.name} is linked to the {source.name} pass, not "
                f"{expected}", "wrong pass")
    return source, valid, None, None


def pass_source(socket, scene, expected):
    """(view layer name, error, short error) of the Render Layers pass feeding
    `socket`; the short error fits the node's status line."""
    source, valid, error, short = _render_layers_pass(socket, expected)
    if source is None:
        return None, error, short
    node = source.node
    refusal = render_layers_refusal(node, scene, socket.name)
    if refusal is not None:
        return (None, *refusal)
    # Blender 3.4 keeps a valid link to a pass the engine does not make, 5.x an invalid one
    if not source.enabled or not valid:
        return (None, f"{socket.name} is linked to the {expected} pass, which "
                f"{compat.engine_label(scene.render.engine)} does not make", "no pass")
    view = handover.named_view(scene)
    longest = handover.longest_layer_name(expected, view)
    if longest is None or len(node.layer.encode()) <= longest:
        return node.layer, None, None
    if view is None:
        why = (f"Blender before 5.0 cuts channel names at {compat.EXR_CHANNEL_NAME_MAX} bytes; "
               f"rename the layer to at most {longest} bytes (it has "
               f"{len(node.layer.encode())})")
    else:
        rename = (f"the layer to at most {longest} bytes, or the view" if longest > 0 else
                  "the view")
        why = (f"Blender before 4.5 names the channels of a render with one view with that "
               f"view, {view!r}, and cuts them past {handover.SINGLE_VIEW_CHANNEL_NAME_MAX} "
               f"bytes; rename {rename}")
    return (None, f"{socket.name} comes from view layer {node.layer!r}, whose name is too long "
            f"for this Blender's EXR files: its {expected} pass cannot be read back ({why})",
            "name too long")


def enable_needed_passes(scene, tree):
    """Turn on the Depth/Normal pass a linked HBAO node reads but the view
    layer lacks; not for a source the node refuses (another scene's: a lasting
    change there, for no AO). Plain settings only: allowed in the render
    job's thread."""
    messages = []
    for node in hbao_nodes(tree):
        if node.mute:
            continue
        for input_name, attribute, label in PASSES:
            socket = node.inputs.get(input_name)
            source = _render_layers_pass(socket, label)[0]
            if source is None or render_layers_refusal(source.node, scene, label) is not None:
                continue
            view_layer = scene.view_layers.get(source.node.layer)
            if view_layer is not None and not getattr(view_layer, attribute):
                setattr(view_layer, attribute, True)
                message = (f"enabled the {label} pass of view layer {view_layer.name!r} "
                           f"for node {node.name!r}")
                messages.append(message)
                log(message)
                # on the node and in the render's report, as the render's
                # own messages are (which would otherwise replace it)
                change = NodeMessage(
                    node.name, f"the {label} pass of view layer {view_layer.name!r} was off; "
                    f"the add-on turned it on (the node reads it)", f"{label} pass turned on")
                note_change(scene.name, change)
                if in_main_thread():  # outside a render: on the node now, as well (the
                    # status timer shows it: one written here, it replaced at its next tick)
                    add_node_messages(scene.name, [change])
    return messages
