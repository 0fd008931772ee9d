# SPDX-License-Identifier: GPL-2.0-or-later
"""Which AO computations a frame needs: one job per HBAO node whose output
someone looks at, with the view layer its passes come from and its
parameters at that frame."""
from . import compat
from .helper_scene import MANAGED_NODE_KEY
from .node import DEPTH_INPUT, NORMAL_INPUT, hbao_nodes, pass_name
from .socket_values import node_params, upstream


class Job:
    def __init__(self, node, layer, with_normal, params):
        self.node_name = node.name
        self.pass_name = pass_name(node)
        self.layer = layer
        self.with_normal = with_normal
        self.params = params


def pass_source(socket, scene, expected):
    """(view layer name, error) of the Render Layers pass feeding `socket`."""
    source = upstream(socket)
    if source is None:
        return None, None
    node = source.node
    if node.bl_idname != "CompositorNodeRLayers" or node.get(MANAGED_NODE_KEY):
        return None, f"{socket.name} must come straight from a Render Layers node"
    if node.scene is not None and node.scene != scene:
        return None, f"{socket.name} comes from another scene ({node.scene.name})"
    if source.identifier != expected and source.name != expected:
        return None, f"{socket.name} is linked to the {source.name} pass, not {expected}"
    return node.layer, None


def plan(main, frame):
    """The AO computations `main` needs at `frame`: ([Job], [warning])."""
    jobs, warnings = [], []
    for node in hbao_nodes(compat.compositor_tree(main)):
        if node.mute:
            continue
        if not any(output.is_linked for output in node.outputs):
            continue  # nobody looks at it: costs nothing
        depth_layer, error = pass_source(node.inputs[DEPTH_INPUT], main, "Depth")
        if depth_layer is None:
            warnings.append(f"{node.name}: {error or 'Depth is not linked'}; AO = 1")
            continue
        normal_layer, error = pass_source(node.inputs[NORMAL_INPUT], main, "Normal")
        if error:
            warnings.append(f"{node.name}: {error}; reconstructing normals from depth")
        try:
            params = node_params(node, frame, warnings)
        except ValueError as value_error:
            warnings.append(f"{value_error}; AO = 1")
            continue
        jobs.append(Job(node, depth_layer, normal_layer == depth_layer, params))
        if normal_layer is not None and normal_layer != depth_layer:
            warnings.append(f"{node.name}: Normal comes from another view layer than Depth; "
                            f"reconstructing normals from depth")
    return jobs, warnings
