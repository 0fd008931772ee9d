# SPDX-License-Identifier: GPL-2.0-or-later
"""Which AO computations a frame needs: one job per HBAO node whose output
someone looks at, with the view layer its passes come from and its
parameters at that frame."""
from . import (compat, extra_renders, helper_lookup, helper_render_settings, pass_capture,
               render_threads)
from .callback_guard import never_raises
from .node import DEPTH_INPUT, NORMAL_INPUT, hbao_nodes, pass_name
from .pass_sources import pass_source
from .report import NodeMessage, post_node_messages, take_changes
from .socket_values import node_params


# A status line's cause (report.NodeMessage): what plan_node said of the node
# at a frame, (PLAN_CAUSE, frame); it holds while plan_node still says it
# (status_causes.py).
PLAN_CAUSE = "plan"


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


def _sources(node, main):
    """Where `node`'s Depth and Normal come from: two pass_source answers,
    (view layer or None, error, short). Read without the library, so that
    render_pre can choose the passes to take where the library is broken."""
    return (pass_source(node.inputs[DEPTH_INPUT], main, "Depth"),
            pass_source(node.inputs[NORMAL_INPUT], main, "Normal"))


def _reads_normal(depth_layer, normal_layer):
    """Whether a job uses its Normal pass: only from Depth's own layer."""
    return normal_layer is not None and normal_layer == depth_layer


def plan_node(node, main, frame, warnings):
    """The Job of one HBAO node, or None when it computes nothing."""
    depth, normal = _sources(node, main)
    depth_layer, error, short = depth
    if depth_layer is None:
        if error is None:
            warnings.append(NodeMessage(node.name, "Depth is not linked; AO off (the node "
                                        "passes Image through)", "Depth not linked: AO off"))
        else:
            warnings.append(NodeMessage(node.name, f"{error}; AO off", f"Depth: {short}, AO off"))
        return None
    normal_layer, error, short = normal
    if error:
        warnings.append(NodeMessage(node.name, f"{error}; reconstructing normals from depth",
                                    f"Normal: {short}, ignored"))
    try:
        params = node_params(node, main, frame, warnings)
    except ValueError as value_error:
        warnings.append(NodeMessage(node.name, f"{value_error}; AO off",
                                    getattr(value_error, "short", "Invalid value: AO off")))
        return None
    if normal_layer is not None and normal_layer != depth_layer:
        warnings.append(NodeMessage(node.name, "Normal comes from another view layer than "
                                    "Depth; reconstructing normals from depth",
                                    "Normal: other layer, ignored"))
    return Job(node, depth_layer, _reads_normal(depth_layer, normal_layer), params,
               render_threads.count(main))


def node_names(main):
    """The names of the HBAO nodes of `main`'s compositor tree."""
    return [node.name for node in hbao_nodes(compat.compositor_tree(main))]


def _computing_nodes(main):
    """The HBAO nodes of `main` that compute: not muted, and someone looks
    at an output (a node nobody looks at costs nothing)."""
    return [node for node in hbao_nodes(compat.compositor_tree(main))
            if not node.mute and any(output.is_linked for output in node.outputs)]


def passes_read(main):
    """{view layer name: whether its Normal is read} of the passes that
    `main`'s computing HBAO nodes read, as their jobs would (plan_node's
    _sources and _reads_normal, without its parameters and the library)."""
    layers = {}
    for node in _computing_nodes(main):
        (depth_layer, _, _), (normal_layer, _, _) = _sources(node, main)
        if depth_layer is not None:
            layers[depth_layer] = (layers.get(depth_layer, False)
                                   or _reads_normal(depth_layer, normal_layer))
    return layers


@never_raises("take the render's passes from memory (they are saved instead)")
def watch_passes(main):
    """Before a frame of `main`: pass_capture takes the passes its helper
    will read, those of its extra renders too (nothing where no helper
    renders)."""
    pass_capture.watch(main, *_passes_to_take(main))


def _passes_to_take(main):
    if not (helper_render_settings.compositor_runs(main)
            and helper_render_settings.helper_renders(main)):
        return {}, []
    helper = helper_lookup.helper_scene_of(main)
    extras = []
    for kind in extra_renders.KINDS if helper is not None else ():
        extra = extra_renders.for_render(main, helper, kind)[0]
        if extra is not None:
            extras.append((extra, {extra.view_layers[0].name: kind.wants_normal}))
    return passes_read(main), extras


def plan(main, frame):
    """The AO computations `main` needs at `frame`: ([Job], [NodeMessage]).
    The messages are also posted for the nodes' status lines (each node of
    the tree gets its own, or none: a good frame clears an old status)."""
    jobs, warnings = [], []
    for node in _computing_nodes(main):
        found = []
        job = plan_node(node, main, frame, found)
        for message in found:
            message.cause = (PLAN_CAUSE, frame)
        warnings += found
        if job is not None:
            jobs.append(job)
    # What the add-on changed (a pass turned on) after the problems, so that
    # a node's status line leads with why its AO is off
    warnings += take_changes(main.name)
    post_node_messages(main.name, node_names(main), warnings)
    return jobs, warnings


def tell_all_nodes(main, short, detail, cause=None):
    """The same message on every HBAO node of `main` (None: nothing): a
    render whose AO failed as a whole."""
    if main is None:
        return
    names = node_names(main)
    post_node_messages(main.name, names,
                       [NodeMessage(name, detail, short, cause) for name in names])
