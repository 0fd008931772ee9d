# SPDX-License-Identifier: GPL-2.0-or-later
"""Which AO computations a frame needs: one job per HBAO node whose output
someone looks at, with the view layer its passes come from and its
parameters at that frame."""
from . import compat, handover, render_threads
from .helper_lookup import MANAGED_NODE_KEY
from .node import DEPTH_INPUT, NORMAL_INPUT, hbao_nodes, pass_name
from .report import NodeMessage, post_node_messages, take_changes
from .socket_values import node_params, upstream


class Job:
    def __init__(self, node, layer, with_normal, params, threads):
        self.node_name = node.name
        self.pass_name = pass_name(node)
        self.layer = layer
        self.with_normal = with_normal
        self.params = params
        # the AO's threads (render_threads): not a parameter, as the AO
        # is the same for any number, so they change no cache or record
        self.threads = threads
        # of the frame on each side, guard_geometry's
        self.guard_band = node.guard_band / 100.0
        self.back_faces = node.back_faces


def pass_source(socket, scene, expected):
    """(view layer name, error, short error) of the Render Layers pass feeding
    `socket`; the short error fits the node's status line."""
    source = upstream(socket)
    if source is None:
        return None, None, None
    node = source.node
    if node.bl_idname != "CompositorNodeRLayers" or node.get(MANAGED_NODE_KEY):
        return (None, f"{socket.name} must come straight from a Render Layers node",
                "wrong source")
    if node.scene is not None and node.scene != scene:
        return (None, f"{socket.name} comes from another scene ({node.scene.name})",
                "other scene")
    if source.identifier != expected and source.name != expected:
        return (None, f"{socket.name} is linked to the {source.name} pass, not {expected}",
                "wrong pass")
    if node.mute:
        return None, f"{socket.name} comes from a muted Render Layers node ({node.name})", "muted"
    if not source.enabled:  # Blender 3.4 keeps the link to a pass the engine does not make
        return (None, f"{socket.name} is linked to the {expected} pass, which the render engine "
                "does not make", "no such pass")
    view_layer = (node.scene or scene).view_layers.get(node.layer)
    if view_layer is not None and not view_layer.use:
        return (None, f"{socket.name} comes from view layer {node.layer!r}, which is not rendered "
                "(its Use for Rendering is off)", "not rendered")
    longest = handover.longest_layer_name(expected)
    if longest is not None and len(node.layer.encode()) > longest:
        return (None, f"{socket.name} comes from view layer {node.layer!r}, whose name is too "
                f"long for this Blender's EXR files: its {expected} pass cannot be read back "
                f"(Blender before 5.0 cuts channel names at {compat.EXR_CHANNEL_NAME_MAX} "
                f"bytes; rename the layer to at most {longest})", "name too long")
    return node.layer, None, None


def plan_node(node, main, frame, warnings):
    """The Job of one HBAO node, or None when it computes nothing."""
    depth_layer, error, short = pass_source(node.inputs[DEPTH_INPUT], main, "Depth")
    if depth_layer is None:
        if error is None:
            warnings.append(NodeMessage(node.name, "Depth is not linked; AO off (the node "
                                        "passes Image through)", "Depth not linked: AO off"))
        else:
            warnings.append(NodeMessage(node.name, f"{error}; AO off", f"Depth: {short}, AO off"))
        return None
    normal_layer, error, short = pass_source(node.inputs[NORMAL_INPUT], main, "Normal")
    if error:
        warnings.append(NodeMessage(node.name, f"{error}; reconstructing normals from depth",
                                    f"Normal: {short}, ignored"))
    try:
        params = node_params(node, frame, warnings)
    except ValueError as value_error:
        warnings.append(NodeMessage(node.name, f"{value_error}; AO off",
                                    getattr(value_error, "short", "Invalid value: AO off")))
        return None
    if normal_layer is not None and normal_layer != depth_layer:
        warnings.append(NodeMessage(node.name, "Normal comes from another view layer than "
                                    "Depth; reconstructing normals from depth",
                                    "Normal: other layer, ignored"))
    return Job(node, depth_layer, normal_layer == depth_layer, params,
               render_threads.count(main))


def node_names(main):
    """The names of the HBAO nodes of `main`'s compositor tree."""
    return [node.name for node in hbao_nodes(compat.compositor_tree(main))]


def plan(main, frame):
    """The AO computations `main` needs at `frame`: ([Job], [NodeMessage]).
    The messages are also posted for the nodes' status lines (each node of
    the tree gets its own, or none: a good frame clears an old status)."""
    jobs, warnings = [], take_changes(main.name)
    nodes = hbao_nodes(compat.compositor_tree(main))
    for node in nodes:
        if node.mute:
            continue
        if not any(output.is_linked for output in node.outputs):
            continue  # nobody looks at it: costs nothing
        job = plan_node(node, main, frame, warnings)
        if job is not None:
            jobs.append(job)
    post_node_messages(main.name, node_names(main), warnings)
    return jobs, warnings


def tell_all_nodes(main, short, detail):
    """The same message on every HBAO node of `main` (None: nothing): a
    render whose AO failed as a whole."""
    if main is None:
        return
    names = node_names(main)
    post_node_messages(main.name, names, [NodeMessage(name, detail, short) for name in names])
